"""The version of mpm_warp."""

__version__ = "0.1.0"
