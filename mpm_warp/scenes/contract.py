"""The contract of a snow scene: typed parameters, a builder and a monitor.

A scene kind (``"pst"``, ``"shear_test"``) is one :class:`SceneType`:

- ``params``: a frozen dataclass of the scene's parameters with units in its docstring (nested
  dataclasses for its parts, ``Literal`` choices), a class attribute ``kind``, ``validate(where)``
  (every value checked, the error naming ``where.field``) and ``to_dict()`` (the ``[scene]`` table the
  loader reads back). Derived values (saw times, marker stations, references) are its methods;
- ``build(params, time, output=None, *, name, precision, description) -> Scenario``: the domain,
  materials, blocks, walls and the ``[time]`` settings the scene owns (``time_keys``: gravity and
  settling), with the parameters kept in :attr:`Scenario.scene`;
- ``attach(sim) -> Monitor``: builds the scene's monitor (device actions, frame scalars, checkpoint
  state, results; the engine's contract is :class:`mpm_warp.monitor.Monitor`) and adds it with
  :meth:`mpm_warp.Simulation.add_monitor`.

``mpm_warp.run`` builds the scene, attaches its monitor and returns the monitor's result; the
registry by kind is :data:`mpm_warp.scenes.SCENES`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..monitor import Monitor

__all__ = ["SceneType", "Monitor"]


@dataclass(frozen=True)
class SceneType:
    """One scene kind (see the module docstring).

    Attributes
    ----------
    kind : str
        Name in ``[scene] kind = ...``.
    description : str
        One line for ``mpm-warp scenes``.
    params : type
        The parameter dataclass.
    build : callable
        ``build(params, time, output=None, *, name, precision, description) -> Scenario``.
    attach : callable
        ``attach(sim) -> Monitor``.
    time_keys : tuple of str
        ``[time]`` keys the scene sets itself (a scenario file may not give them).
    upgrade : callable or None
        ``upgrade(table) -> table``: a ``[scene]`` table of an older release (a stored run file) in today's
        keys, before it is read.
    expand : callable or None
        ``expand(table, base_dir) -> table``: a scenario file's ``[scene]`` table with what it refers to read in
        (a PST's snow profile into layers), once, when the file is loaded; stored run files hold the result.
    """

    kind: str
    description: str
    params: type
    build: Callable
    attach: Callable
    time_keys: tuple[str, ...] = ()
    upgrade: Callable | None = None
    expand: Callable | None = None
