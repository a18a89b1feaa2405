"""A simulation's frames: the run file's layout (fields, static data, attributes) and one frame's record.

A frame's record is taken once per frame whether or not it is written: it also resets what the
frame collects (the wall impulses, the ``yielded`` flags) and lets the monitors record their
series, so a resumed run that steps again over frames its file holds already (:meth:`Simulation.run`
with ``append``) keeps every series as an uninterrupted run would.
"""

from __future__ import annotations

import errno
import os
import secrets

import numpy as np

from . import io
from .config import OUTPUT_FIELDS
from .errors import InvalidArgument
from .result import versions

__all__ = ["open_writer", "particle_field", "frame_record", "write_frame", "frame_diagnostics", "new_run_id",
           "out_of_space"]


def new_run_id() -> str:
    """A random identity of a run file (32 hex digits), stored in its attributes and in its checkpoints."""
    return secrets.token_hex(16)


def open_writer(sim, path: str) -> io.RunWriter:
    """Create the run file ``path`` of simulation ``sim`` (layout from its scenario and monitors)."""
    sc, model = sim.scenario, sim.model
    pf = {}
    for name in sc.output.fields:
        shape, unit, _ = OUTPUT_FIELDS[name]
        shape = tuple(model.dim if c == "dim" else c for c in shape)
        pf[name] = (shape, "uint8" if name == "yielded" else sc.precision, unit)
    for m in sim.monitors.values():
        for name, (shape, unit) in getattr(m, "particle_fields", dict)().items():
            pf[name] = (shape, sc.precision, unit)
    group_id = np.zeros(model.n_particles, dtype=np.min_scalar_type(max(len(model.groups) - 1, 0)))
    for i, g in enumerate(model.groups):
        group_id[g.start:g.end] = i
    static = {"x0": (sim.x0.astype(model.np_dtype), "m"), "group": (group_id, "1")}
    scalars = series_units(sim)
    attrs = {
        "scenario": sc.to_dict(),
        "versions": versions(),
        "device": sim.device,
        "precision": sc.precision,
        "groups": [{"name": g.name, "material": g.material_name, "start": g.start, "end": g.end,
                    "mass": g.mass, "vol0": g.vol0} for g in model.groups],
        "unit_system": "SI: m, s, kg, Pa, N, J",
        "grid": {"origin": list(model.origin), "shape": list(model.grid_shape), "dx": model.dx},
    }
    if sim.run_id is not None:
        attrs["run_id"] = sim.run_id
    return io.RunWriter(path, n_particles=model.n_particles, particle_fields=pf, static_fields=static,
                        wall_names=model.wall_names, scalar_series=scalars, attrs=attrs)


def particle_field(sim, name: str) -> np.ndarray:
    """Host copy of output field ``name`` (:data:`~mpm_warp.config.OUTPUT_FIELDS`) for all particles of ``sim``.

    ``yielded`` is the flag of the frame: reading it clears it for the next."""
    s = sim.state
    n = sim.model.n_particles
    if name in ("x", "v"):
        return getattr(s, name).numpy()
    if name == "F":
        return s.elastic_deformation_gradient().astype(sim.model.np_dtype)
    if name == "stress":
        return sim.stresses(cauchy=True)[2]
    if name in ("log_jp", "kappa"):
        out = np.zeros(n, dtype=sim.model.np_dtype)
        arr = getattr(s, name)
        if arr is not None:
            a = arr.numpy()
            for g in sim.model.groups:
                at = g.plastic_start if name == "log_jp" else g.kappa_start
                if at >= 0:
                    out[g.start:g.end] = a[at:at + g.count]
        return out
    if name == "damage":
        out = np.zeros(n, dtype=sim.model.np_dtype)
        if s.kappa is not None:
            a = s.kappa.numpy().astype(np.float64)
            for g in sim.model.groups:
                k = a[g.kappa_start:g.kappa_start + g.count] if g.kappa_start >= 0 else None
                if g.material.model == "tensile_cracking":
                    out[g.start:g.end] = g.material.damage(k)
                elif g.material.model == "bonded_camclay":
                    out[g.start:g.end] = np.minimum(1.0, k / g.material.kappa_s)
        return out
    if name in ("p", "q"):
        p, q = sim.stress_invariants()
        return p if name == "p" else q
    if name == "yielded":
        out = np.zeros(n, dtype=np.uint8)
        if s.yielded is not None:
            y = s.yielded.numpy()
            for g in sim.model.groups:
                if g.plastic_start >= 0:
                    out[g.start:g.end] = y[g.plastic_start:g.plastic_start + g.count]
            s.yielded.zero_()
        return out
    raise InvalidArgument("field", name, "one of " + ", ".join(OUTPUT_FIELDS))


def frame_diagnostics(sim) -> dict:
    """The monitors' frame scalars (also without an output file: they may record series)."""
    out = {}
    for m in sim.monitors.values():
        out.update(m.frame_scalars(sim))
    return out


def frame_record(sim) -> tuple[float, int, dict, np.ndarray | None, dict]:
    """``(time [s], step, particle fields, wall forces [N] or None, scalars)`` of the frame ``sim`` is at."""
    t, _, steps = sim.stepper.clock()
    parts = {name: sim.particle_field(name) for name in sim.scenario.output.fields}
    for m in sim.monitors.values():
        parts.update({name: m.particle_field(name) for name in getattr(m, "particle_fields", dict)()})
    scalars = sim.energies()
    scalars.update(frame_diagnostics(sim))
    imp = sim.stepper.take_wall_impulse()
    # mean force over the frame just ended (its real duration: the last frame may be short)
    span = t - getattr(sim, "_last_frame_time", t)
    sim._last_frame_time = t
    forces = (imp / span if span > 0 else np.zeros_like(imp)) if len(imp) else None
    if forces is not None and forces.shape[1] < 3:  # plane strain: N per metre of depth, z component 0
        forces = np.pad(forces, ((0, 0), (0, 3 - forces.shape[1])))
    return t, steps, parts, forces, scalars


def series_units(sim) -> dict[str, str]:
    """The frame series ``sim`` records, name -> unit: the energies, then each monitor's."""
    scalars = {"kinetic_energy": "J", "elastic_energy": "J"}
    for m in sim.monitors.values():
        scalars.update(m.units())
    return scalars


def write_frame(sim, writer: io.RunWriter, left_out: frozenset = frozenset()) -> None:
    """Append the frame ``sim`` is at to ``writer``, less the series ``left_out`` (those a resumed run's file,
    written by an older release, does not hold)."""
    t, steps, parts, forces, scalars = frame_record(sim)
    for name in left_out:
        scalars.pop(name, None)
    writer.write_frame(t, steps, parts, wall_forces=forces, scalars=scalars)


def out_of_space(err: io.OutOfSpace, output: str) -> io.OutOfSpace:
    """``err`` (a write of run ``output`` found no room) told as what is safe and how to go on, in one line."""
    n, t = getattr(err, "frames", None), getattr(err, "last_time", None)   # a frame's write: its writer knows
    if n is None:
        try:
            run = io.read_run(output)
            n, t = run.n_frames, float(run.times[-1]) if run.n_frames else None
        except (io.OutputError, IndexError):
            n = 0
    safe = f"{n} complete frame{'s are' if n != 1 else ' is'} safe in {output}" + (f" (to t = {t:.6g} s)" if n else "")
    try:
        short = os.path.getsize(output) < (io.hdf5.stored_eof(output) or 0)
    except OSError:
        short = False
    if short:                  # the failed flush left it short of its end, and there was no room to pad it
        safe += " (readers refuse it as truncated until the resume pads its incomplete last frame)"
    ckpt = io.checkpoint_path_for(output)
    room = {errno.EDQUOT: "free space or raise the quota",
            errno.EFBIG: "raise the file-size limit (ulimit -f)"}.get(err.errno, "free space")
    if os.path.exists(ckpt) and io.checkpoint_is_intact(ckpt):
        t = io.read_checkpoint_meta(ckpt)["time"]
        how = f"{room}, then resume from its checkpoint (t = {t:.6g} s): mpm-warp resume {output}"
    else:
        how = f"there is no checkpoint to resume from: {room}, then run again with --overwrite"
    out = io.OutOfSpace(err.path, err.errno, err.what)
    out.args, out.frames = (f"{err}; {safe}; {how}",), n
    return out
