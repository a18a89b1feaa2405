"""Error hierarchy of mpm_warp.

One small hierarchy, as in Devito: every error the library raises on purpose
derives from :class:`MPMError`, so callers can catch them all at once.
"""

from __future__ import annotations

__all__ = ["MPMError", "InvalidArgument", "ScenarioError", "SimulationBlowUp", "OutputError", "RenderingUnavailable"]


class MPMError(Exception):
    """Base class of every error raised on purpose by mpm_warp."""


class InvalidArgument(MPMError, ValueError):
    """A parameter is outside its allowed range.

    The message always names the field, the value received and what is allowed.
    """

    def __init__(self, field: str, value, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field} = {value!r} is invalid: expected {allowed}")


class ScenarioError(MPMError, ValueError):
    """A scenario file cannot be read: bad TOML, unknown or missing keys, wrong types."""


class SimulationBlowUp(MPMError, RuntimeError):
    """The health check found a non-finite or runaway state.

    Attributes
    ----------
    step : int
        Step at which the problem was detected.
    particle : int
        Index of the first offending particle (-1 if not particle-specific).
    field : str
        Name of the field that failed (``"v"``, ``"F"``, ``"x"``, ...).
    cause : str
        Human-readable cause.
    checkpoint : str or None
        Path of the last checkpoint, if one was written and verifies (its checksum matches).
    """

    def __init__(self, step: int, particle: int, field: str, cause: str, checkpoint: str | None = None,
                 output: str | None = None):
        self.step = step
        self.particle = particle
        self.field = field
        self.cause = cause
        self.checkpoint = checkpoint
        self.output = output
        who = f"particle {particle}, " if particle >= 0 else ""
        msg = f"simulation stopped at step {step}: {who}field {field!r}: {cause}"
        if output:
            msg += f"; complete frames kept in {output}"
        if checkpoint:
            msg += f"; last good checkpoint {checkpoint} (resume with `mpm-warp resume`)"
        super().__init__(msg)


class RenderingUnavailable(MPMError, RuntimeError):
    """No OpenGL back end for off-screen rendering (or no encoder for the film) on this machine."""


class OutputError(MPMError, OSError):
    """An output file is missing, incomplete or not an mpm_warp run."""
