"""The field protocol: how a field case is run, as an observer runs a PST, within a per-case budget.

- **The saw** starts at the upslope end after settling and may cut to the column's far end; where the scene
  supports it (``saw.stop = "runaway"``) it stops once the crack runs away from it, so that what follows is
  the crack's own. A crack that never runs away before the saw reaches the end is "no propagation".
- **The grid** resolves the weak layer with 4 cells (the resolution the snow ladders call resolved) when the
  column then fits :attr:`FieldProtocol.max_particles`; else with 3, the fewest the model allows; else the
  column runs with an equivalent weak layer, thicker, with the real layer's fracture energy, strength, collapse
  height and stiffness per unit area (:mod:`.equivalent_layer`), at 4 cells or else 3; else the case is refused
  in one line (the column is too large for the budget). A brittle slab's crack band (1.5 cells) must stay below
  its snap-back length ``2 E G_f / sigma_t^2``: where that needs a finer grid, the grid is refined to it.
- **The pre-cut**: each column starts sawn half of weac's critical cut at its fracture energy
  (``pre_cut_share``), as a slow saw would leave it; the blade goes on from there.
- **The base**: the weak layer lies on a rigid base (``scene.rigid_base``), the column that weac reads the
  fracture energy back with; the old snow under it is left out (docs/field.md, "The field protocol").
- **The interfaces** (optional, off by default): the laminate closure (``interface_closure``, docs/model.md §5b)
  at the column's layer interfaces.
- **The run** lasts the settling, the saw's way to the end, and :attr:`FieldProtocol.tail` after it, and stops
  at the first frame at which the outcome is decided (END, SF, an arrest after a runaway, no propagation).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..config import TimeControl
from ..errors import InvalidArgument
from ..scenes.pst import PSTParams
from ..scenes.pst.params_checks import band_limited_dx
from .equivalent_layer import equivalent_layer, equivalent_params, particle_estimate

__all__ = ["FieldProtocol", "protocol_params", "protocol_column", "protocol_equivalent", "decided",
           "particle_estimate", "run_to_decision", "run_until_decided"]


@dataclass(frozen=True)
class FieldProtocol:
    """How field cases run.

    Attributes
    ----------
    max_particles : int
        The per-case budget: most particles a column may have (2D).
    cells_across : int
        Grid cells across the weak layer when the budget allows (else 3).
    saw_speed : float
        Blade speed (m/s).
    tail : float
        Simulated time after the saw reached the far end (s).
    frame_interval : float
        Time between frames (s): the outcome is checked at every frame.
    rigid_base : bool
        Run the weak layer on a rigid base (the default), or on the profile's old snow (False).
    pre_cut_share : float
        The saw's pre-cut (``scene.saw.pre_cut``) as a share of weac's critical cut of the column at its fracture
        energy, in [0, 0.9]: the column starts sawn that far, sparing the simulated time of sawing it (0.5, the
        default: docs/field.md); 0: the saw cuts from the end.
    interface_closure : bool
        Run the column with the laminate closure at its layer interfaces (``scene.interface_closure``,
        docs/model.md §5b), or without it (False, the default).
    threads : int
        CPU threads each case's step runs on (the CPU step's own threads; ignored on CUDA). A batch's workers
        times this should not exceed the cores: on 2 cores, 1 worker of 2 threads finishes each case sooner
        (the median case's wall time), 2 workers of 1 thread finish more cases an hour.
    columns : int
        Columns stepped together in one task (:mod:`mpm_warp.column_batch`), each on one thread, with one step
        size: the least of theirs. 1 (the default): each case alone. Many columns fill a GPU that one column
        leaves idle; a column then steps at most as long as alone, and its key (so its id) says it shares its
        step: a case's numbers then depend on its group's stiffest column, within the step's discretisation error.
    """

    max_particles: int = 120_000
    cells_across: int = 4
    saw_speed: float = 1.0
    tail: float = 0.3
    frame_interval: float = 0.005
    rigid_base: bool = True
    pre_cut_share: float = 0.5
    interface_closure: bool = False
    threads: int = 1
    columns: int = 1

    def validate(self) -> FieldProtocol:
        """Check every value (one-line InvalidArgument naming it); return self."""
        from ..checks import finite_number, positive_int

        positive_int("max_particles", self.max_particles, lo=1000)
        positive_int("cells_across", self.cells_across, lo=3, hi=16)
        finite_number("saw_speed", self.saw_speed, lo=0.0, lo_open=True, hi=1.0)
        finite_number("tail", self.tail, lo=0.0)
        finite_number("frame_interval", self.frame_interval, lo=0.0, lo_open=True, hi=0.1)
        positive_int("threads", self.threads, lo=1, hi=64)
        positive_int("columns", self.columns, lo=1, hi=4096)
        for name in ("rigid_base", "interface_closure"):
            if not isinstance(getattr(self, name), bool):
                raise InvalidArgument(name, getattr(self, name), "true or false")
        finite_number("pre_cut_share", self.pre_cut_share, lo=0.0, hi=0.9)
        return self

    def run_key(self) -> dict:
        """The fields that change what a case computes (all but ``threads``): a cached case is reused only under
        the same ones. ``interface_closure`` is left out while off, and ``columns`` while 1, so that the cases
        run before they existed keep their keys."""
        d = dataclasses.asdict(self)
        del d["threads"]
        if not self.interface_closure:
            del d["interface_closure"]
        if self.columns == 1:
            del d["columns"]
        return d


def protocol_column(params: PSTParams, proto: FieldProtocol) -> PSTParams:
    """The column ``params`` with the protocol's base and interfaces, before its grid and saw are set."""
    if proto.interface_closure:
        params = dataclasses.replace(params, interface_closure=True)
    if proto.rigid_base:
        bare = PSTParams()
        params = dataclasses.replace(params, rigid_base=True, substratum_layers=(), substratum=bare.substratum,
                                     substratum_thickness=bare.substratum_thickness)
    return params


def _fits(params: PSTParams, proto: FieldProtocol) -> bool:
    """Whether the protocol's column ``params`` fits the budget with its own weak layer at 3 cells or more."""
    return particle_estimate(dataclasses.replace(params, dx=params.weak_layer_thickness / 3)) <= proto.max_particles


def protocol_equivalent(params: PSTParams, proto: FieldProtocol):
    """The :class:`~.equivalent_layer.EquivalentLayer` the case ``params`` runs with under ``proto``, None when it
    needs none (its own layer fits the budget), or the line saying why none fits (str). Arithmetic only."""
    params = protocol_column(params, proto)
    if _fits(params, proto):
        return None
    return equivalent_layer(params, dict.fromkeys((proto.cells_across, 3)), proto.max_particles)


def protocol_params(params: PSTParams, proto: FieldProtocol, static_cut: float | None = None
                    ) -> tuple[PSTParams | None, TimeControl | None, str]:
    """The field case ``params`` as the protocol runs it: ``(params, time, note)``, or ``(None, None, reason)``.

    ``static_cut`` is weac's critical cut of the column (m; None: not critical, or not asked for), the pre-cut's
    measure when the protocol has one. A column over the budget at 3 cells runs with an equivalent weak layer
    (:func:`protocol_equivalent`), which its note names.
    """
    params = protocol_column(params, proto)
    saw_fields = {f.name for f in dataclasses.fields(params.saw)}
    pre = proto.pre_cut_share * static_cut if proto.pre_cut_share > 0.0 and static_cut else 0.0
    saw = dataclasses.replace(params.saw, cut_length=float(params.length), speed=proto.saw_speed,
                              **({"stop": "runaway"} if "stop" in saw_fields else {}),
                              **({"pre_cut": min(pre, 0.5 * float(params.length))} if pre > 0.0 else {}))
    grids = [(cells, params.weak_layer_thickness / cells, None) for cells in (proto.cells_across, 3)]
    if not _fits(params, proto):
        eq = protocol_equivalent(params, proto)
        if isinstance(eq, str):
            n = particle_estimate(dataclasses.replace(params, dx=params.weak_layer_thickness / 3))
            return None, None, (f"the column is too large for the per-case budget: {n:,} particles at the coarsest "
                                f"grid the weak layer allows (3 cells), above {proto.max_particles:,}; {eq}")
        grids, params = [(eq.cells, eq.dx, eq)], equivalent_params(params, eq.equivalent_thickness)
    fine = band_limited_dx(params)          # a brittle slab's crack band may need a finer grid than the layer's
    for cells, dx, eq in grids:
        dx = min(dx, fine)
        p = dataclasses.replace(params, dx=dx, margin=max(params.margin, 2.0 * dx), saw=saw)
        n = particle_estimate(p)
        if n <= proto.max_particles:
            end = p.saw_start + (p.length - p.saw.pre_cut) / proto.saw_speed + proto.tail
            grid = (f"{cells} cells across the weak layer" if dx < fine else
                    f"{p.weak_layer_thickness / dx:.1f} cells across the weak layer, as the slab's crack band needs")
            note = ((f"{eq.note()}, " if eq is not None else "")
                    + f"{grid}, dx {dx * 1e3:.2f} mm, about {n:,} particles"
                    + (", on a rigid base" if proto.rigid_base else "")
                    + (", laminate closure" if proto.interface_closure else "")
                    + (f", pre-cut {p.saw.pre_cut * 100:.1f} cm" if p.saw.pre_cut > 0.0 else ""))
            return p.validate("scene"), TimeControl(end=end, frame_interval=proto.frame_interval), note
    # only a brittle slab's finer grid gets here: the weak layer alone fits at 3 cells
    return None, None, (f"the column is too large for the per-case budget: {n:,} particles at the grid its slab's "
                        f"crack band needs (dx {dx * 1e3:.2f} mm: the slab's snow is too brittle for a coarser one), "
                        f"above {proto.max_particles:,}")


def decided(sim) -> bool:
    """Whether the PST running in ``sim`` has its outcome (END, SF, or an arrest or no propagation once the saw is
    done): the batch stops a run there."""
    return sim.monitors["pst"].outcome().get("class") is not None


def run_to_decision(scenario, path: str, *, device: str | None = "cpu", n_threads: int | None = 1):
    """Run a field column's ``scenario`` into ``path`` (overwritten) until its outcome is decided (:func:`decided`),
    as a batch does: ``(result, threads)``, the runner's :class:`~mpm_warp.runner.RunResult` and the CPU threads
    the step really ran on."""
    from ..runner import run

    used = {}

    def until_decided(sim, frame):
        used["threads"] = sim.stepper.n_threads
        return not decided(sim)

    res = run(scenario, path, device=device, overwrite=True, n_threads=n_threads, callback=until_decided)
    return res, used.get("threads")


def run_until_decided(scenario, path: str, n_threads: int = 1) -> dict:
    """Run a field column's ``scenario`` on the CPU into ``path`` (overwritten) until its outcome is decided, as a
    batch does (:func:`run_to_decision`): the row the field studies compare (``predicted``, ``runaway_cut`` (m),
    ``slab_fracture_at`` (m), ``particles``, ``steps``, ``wall_s`` (s), ``sim_time`` (s))."""
    res, _ = run_to_decision(scenario, path, device="cpu", n_threads=n_threads)
    o = res.scene_result.get("outcome", {})
    return {"predicted": o.get("class"), "runaway_cut": res.scene_result.get("runaway_cut"),
            "slab_fracture_at": o.get("slab_fracture_at"), "particles": res.n_particles, "steps": res.steps,
            "wall_s": res.wall_time, "sim_time": res.sim_time}
