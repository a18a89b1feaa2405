"""Derived particle fields of a run file, each defined once here with its reference state.

=================  ===========================================  =====  ====================================
name               definition                                   unit   reference state
=================  ===========================================  =====  ====================================
``collapse``       ``1 - exp(log_jp - log_jp_ref)``: plastic     -      the run's ``log_jp_ref`` field when
                   volume lost since the reference (dilation,           stored (a snow scene with ``log_jp`` in
                   and a sawn cut, are negative)                        its output: the weak layer's state at the
                                                                        end of settling; ``log_jp``
                                                                        elsewhere),
                                                                        else the initial state (frame 0)
``displacement``   ``|x - x0|``                                 m      initial positions (static ``x0``)
``velocity``       ``|v|``                                      m/s    -
``p``, ``q``       stored Kirchhoff pressure and Mises stress   Pa     -
``sigma_yy``       Cauchy normal stress on the bed plane        Pa     - (tension positive)
``sigma_xy``       Cauchy shear stress on the bed plane         Pa     -
=================  ===========================================  =====  ====================================

The collapse of the weak layer is measured from its settled state, not from ``log_jp = 0``: the
initial consolidation (``log_jp(0) = -asinh(p0_ini/K)/xi``) is not a collapse, so ``1 - exp(log_jp)``
would show the intact, settled layer as collapsed. The PST and shear-test monitors store
``log_jp_ref`` per frame (the layer's ``log_jp`` at the end of settling); ``1 - exp(log_jp -
log_jp_ref)`` is then the compaction since settling, the collapse behind the crack front.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..io import RunData
from ..scenes.fronts import collapse_fraction

__all__ = ["DerivedField", "FIELDS", "FieldReader"]


@dataclass(frozen=True)
class DerivedField:
    """One derived particle field.

    Attributes
    ----------
    name, label, unit : str
    needs : tuple of str
        Particle fields the run must store.
    reference : str
        Its reference state, in words.
    compute : callable
        ``compute(frame, reader) -> ndarray (N,)``, float64.
    """

    name: str
    label: str
    unit: str
    needs: tuple
    reference: str
    compute: Callable


def _collapse(frame: dict, reader: FieldReader) -> np.ndarray:
    ref = frame["log_jp_ref"] if "log_jp_ref" in frame else reader.initial("log_jp")
    return collapse_fraction(frame["log_jp"], ref)


def _stress(i: int, j: int) -> Callable:
    return lambda frame, reader: frame["stress"][:, i, j].astype(np.float64)


FIELDS: dict[str, DerivedField] = {f.name: f for f in (
    DerivedField("collapse", "collapse 1 - J_P/J_P,ref", "-", ("log_jp",),
                 "log_jp_ref (settled weak layer, or right after failure) if stored, else frame 0", _collapse),
    DerivedField("displacement", "displacement", "m", ("x",), "initial positions x0",
                 lambda frame, reader: np.linalg.norm(frame["x"].astype(np.float64) - reader.x0(), axis=1)),
    DerivedField("p", "pressure p", "Pa", ("p",), "-", lambda frame, reader: frame["p"].astype(np.float64)),
    DerivedField("q", "Mises stress q", "Pa", ("q",), "-", lambda frame, reader: frame["q"].astype(np.float64)),
    DerivedField("sigma_xy", "shear stress sigma_xy", "Pa", ("stress",), "-", _stress(0, 1)),
    DerivedField("sigma_yy", "normal stress sigma_yy", "Pa", ("stress",), "-", _stress(1, 1)),
    DerivedField("velocity", "speed", "m/s", ("v",), "-",
                 lambda frame, reader: np.linalg.norm(frame["v"].astype(np.float64), axis=1)),
)}


class FieldReader:
    """Evaluates :data:`FIELDS` on the frames of one run file (reference states read once).

    Parameters
    ----------
    run : RunData
    """

    def __init__(self, run: RunData):
        self.run = run
        self._cache: dict[str, np.ndarray] = {}

    def missing(self, name: str) -> list[str]:
        """What the run lacks for field ``name`` (empty when it can be evaluated)."""
        out = [n for n in FIELDS[name].needs if n not in self.run.particle_fields]
        if name == "displacement" and "x0" not in self.run.static:
            out.append("static x0")
        return out

    def x0(self) -> np.ndarray:
        """Initial positions (m), float64."""
        if "x0" not in self._cache:
            self._cache["x0"] = self.run.static["x0"].astype(np.float64)
        return self._cache["x0"]

    def initial(self, field: str) -> np.ndarray:
        """Particle field ``field`` at the initial state (frame 0), float64."""
        key = "initial/" + field
        if key not in self._cache:
            self._cache[key] = self.run.frame(0)[field].astype(np.float64)
        return self._cache[key]

    def values(self, name: str, frame: dict) -> np.ndarray:
        """Field ``name`` on one frame (a dict of particle fields, as :meth:`RunData.frame` gives), (N,)."""
        return np.asarray(FIELDS[name].compute(frame, self), dtype=np.float64).reshape(-1)
