"""The whole state of a run as host arrays: checkpoints, resume, and forks of a run.

A snapshot is ``(arrays, meta)``: the particle state and clock (:meth:`mpm_warp.state.State.arrays`),
the next step's speed bound, a frame's part-collected wall impulses and every monitor's state
(saw flags, reference fields, arrival times, series), with the frame count and the scenario in
``meta``. Loaded into a simulation of the same scenario it continues bit for bit on the CPU
(:func:`restore_run` for a run file's checkpoint); loaded into a simulation whose scenario differs
only in what has not acted yet (a saw that stops later or earlier than the snapshot's time) it is a
*fork*: :mod:`mpm_warp.scenes.pst.critical_cut` bisects the critical cut that way, sharing the
settling and the common part of the sawing between the trial runs.
"""

from __future__ import annotations

import json

import numpy as np

from . import io
from .errors import OutputError

__all__ = ["take_snapshot", "load_snapshot", "restore_run", "check_identity"]


def take_snapshot(sim) -> tuple[dict[str, np.ndarray], dict]:
    """The state of ``sim`` (a :class:`~mpm_warp.simulation.Simulation`) as ``(arrays, meta)``: host copies that
    later steps leave alone."""
    t, _, steps = sim.stepper.clock()
    meta = {"frame_index": sim.frame_index, "scenario": sim.scenario.to_dict(), "device": sim.device,
            "monitors": sorted(sim.monitors), "time": t, "step": steps,
            "last_frame_time": getattr(sim, "_last_frame_time", t), "run_id": getattr(sim, "run_id", None)}
    arrays = sim.state.arrays()
    # the next step's speed bound, so resume is bit for bit; one number, so any thread count or device resumes
    arrays["vmax"] = np.asarray([sim.stepper.vmax.numpy().max()])
    if sim.stepper.wall_impulses is not None:   # the impulse of a frame stopped half-way
        arrays["wall_impulses"] = np.array(sim.stepper.wall_impulses.numpy(), copy=True)
    for name, m in sim.monitors.items():   # copies: on the CPU a device array's numpy() is a view of it
        arrays.update({f"monitors/{name}/{k}": np.array(a, copy=True) for k, a in m.state().items()})
    return arrays, meta


def load_snapshot(sim, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """Continue ``sim`` from a snapshot: state, step bound, monitors, frame count.

    The simulation must hold the same particles and monitors (attach them first); the scenario
    may differ in what has not acted by the snapshot's time. Raises OutputError on a mismatch.
    """
    if set(meta.get("monitors", [])) != set(sim.monitors):
        raise OutputError(f"the snapshot holds the state of the monitors {sorted(meta.get('monitors', []))}, "
                          f"this simulation has {sorted(sim.monitors)}")
    n = sim.model.n_particles
    if "x" in arrays and len(arrays["x"]) != n:
        raise OutputError(f"the snapshot holds {len(arrays['x'])} particles, this simulation {n}")
    sim.state.load_arrays(arrays)
    if "vmax" in arrays:
        sim.stepper.vmax.fill_(float(np.max(arrays["vmax"])))
    else:
        sim.stepper.seed_vmax()
    for name, m in sim.monitors.items():
        prefix = f"monitors/{name}/"
        m.load_state({k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)})
    if "wall_impulses" in arrays and sim.stepper.wall_impulses is not None:
        imp = arrays["wall_impulses"]
        if imp.shape[:2] != sim.stepper.wall_impulses.shape:   # another thread count: the sum in one slot
            imp = np.concatenate([imp.sum(axis=0, keepdims=True),
                                  np.zeros((sim.stepper.wall_impulses.shape[0] - 1, *imp.shape[1:]))])
        sim.stepper.wall_impulses.assign(imp)
    sim.frame_index = int(meta["frame_index"])
    sim._last_frame_time = float(meta.get("last_frame_time", sim.time))


def check_identity(output: str, ckpt: str, run_attrs: dict, meta: dict) -> None:
    """Refuse a checkpoint that is not of this run file: their ``run_id`` differ (or one of them has none).

    Files written before run ids existed (neither has one) are accepted when the checkpoint's scenario
    equals the run file's (frame interval, materials, scene: every key both hold; a key a later version
    added to its checkpoints is not a difference), else refused the same way.
    """
    mine, theirs = run_attrs.get("run_id"), meta.get("run_id")
    if mine is None and theirs is None:
        same = _alike(_plain(run_attrs.get("scenario")), _plain(meta.get("scenario")))
        why = "its scenario differs from the run file's"
    else:
        same = mine == theirs
        why = f"run_id {theirs}, the run file's is {mine}"
    if not same:
        raise OutputError(f"{ckpt}: is not the checkpoint of {output} ({why}): resume refused, it would mix two runs "
                          "in one file")


def _alike(a, b) -> bool:
    """``a == b``, where two dicts are compared on the keys both hold."""
    if isinstance(a, dict) and isinstance(b, dict):
        return all(_alike(a[k], b[k]) for k in a.keys() & b.keys())
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_alike(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def _plain(scenario) -> object:
    """A stored scenario as JSON-decoded plain data (run files hold it as JSON text or a dict)."""
    if isinstance(scenario, str):
        try:
            return json.loads(scenario)
        except ValueError:
            return scenario
    return json.loads(io.hdf5.to_json(scenario))


def restore_run(sim, output: str) -> None:
    """Load the last checkpoint of the run file ``output`` into ``sim`` after checking it against the file.

    The checkpoint is verified (SHA-256) and must be of this run (:func:`check_identity`); every frame
    of the file must read (HDF5 checksums: the resume keeps them all), and the frame of the checkpoint
    must equal its state when both are at the same time.
    """
    ckpt = io.checkpoint_path_for(output)
    arrays, meta = io.read_checkpoint(ckpt)
    run = io.read_run(output)
    check_identity(output, ckpt, run.attrs, meta)
    k = int(meta["frame_index"])
    if run.n_frames <= k:
        raise OutputError(f"{output}: holds {run.n_frames} complete frames, its checkpoint {ckpt} is at frame {k}: "
                          "they are not of the same run")
    for i in range(run.n_frames):
        frame = run.frame(i)
        if i == k:
            kept = frame
    if meta.get("time") == run.times[k] and not np.array_equal(kept["x"], arrays["x"]):
        raise OutputError(f"{output}: frame {k} differs from the state of its checkpoint {ckpt} at the same time; "
                          "the file is damaged or not of this run (resume refused: it would keep that frame)")
    if set(meta.get("monitors", [])) != set(sim.monitors):
        raise OutputError(f"{ckpt}: holds the state of the monitors {sorted(meta.get('monitors', []))}, "
                          f"this simulation has {sorted(sim.monitors)}")
    load_snapshot(sim, arrays, meta)
    sim.x0[...] = run.static["x0"]
    sim.run_id = meta.get("run_id")
