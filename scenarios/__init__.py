"""Ready scenes (TOML files), installed as ``mpm_warp.scenarios``."""
