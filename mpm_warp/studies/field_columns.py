"""A small field batch for a device: made-up field columns stepped together, timed beside the CPU.

:func:`made_up_columns` builds ``n`` field-protocol columns (0.6-1.0 m long, 15-30 cm slabs, 0-30 degree
slopes, 3 and 4 cm weak layers, so two grids) from the ready ``pst_demo`` scene, needing neither weac nor Dask.
:func:`time_columns` runs them as one group on the device until each is decided (a first short group compiles the
kernels, not timed), then the first few alone on the CPU on one thread each, and gives cases per hour both ways
and whether each class agrees. The device suite's ``field`` part (benchmarks/perf/device_suite.py) calls it.
"""

from __future__ import annotations

import dataclasses
import time

__all__ = ["made_up_columns", "time_columns"]


def made_up_columns(n: int, quick: bool = False) -> list:
    """``n`` field-protocol scenarios of different columns (``quick``: 2 ms of each, for a smoke run)."""
    from ..field.protocol import FieldProtocol, protocol_params
    from ..loader import load_scenario
    from ..scenes.pst import build

    base = load_scenario("pst_demo", ["scene.substratum_thickness=0.03", "scene.settle.gravity_ramp=0.02",
                                    "scene.settle.duration=0.04"]).scene
    proto = FieldProtocol(pre_cut_share=0.0, frame_interval=0.005, tail=0.1)
    out = []
    for k in range(n):
        wl = 0.03 if k % 2 == 0 else 0.04
        p = dataclasses.replace(base, length=(0.6, 0.8, 1.0)[k % 3], slab_thickness=(0.15, 0.3, 0.2, 0.25)[k % 4],
                                slope_angle=(0.0, 10.0, 20.0, 30.0)[(k // 2) % 4], weak_layer_thickness=wl,
                                weak_layer=dataclasses.replace(base.weak_layer, w_f=(0.1, 0.2, 0.15)[k % 3]))
        params, tc, _ = protocol_params(p, proto)
        if quick:
            tc = dataclasses.replace(tc, end=0.002, frame_interval=0.001)
        out.append(build(params, tc, name=f"field_column_{k}"))
    return out


def _decided(k, sim, frame) -> bool:
    from ..field.protocol import decided

    return not decided(sim)


def _classes(results) -> list:
    return [None if isinstance(r, BaseException) else r.scene_result.get("outcome", {}).get("class") for r in results]


def time_columns(device: str, n: int, alone: int, deadline: float, quick: bool = False) -> dict:
    """Run :func:`made_up_columns` ``(n)`` as one group on ``device`` and the first ``alone`` of them alone on the
    CPU (one thread each, while ``time.time()`` is before ``deadline``); the cost and the agreement.

    Returns
    -------
    dict
        ``group`` (wall s, cases per hour, particles, steps, classes), ``cpu_alone`` (per case wall s and class,
        cases per hour on one core), ``same_class`` (of the cases run both ways) and ``speedup`` (cases per hour on
        the device over one CPU core).
    """
    import warp as wp

    from ..column_batch import run_columns
    from ..runner import simulation_for

    scenarios = made_up_columns(n, quick)
    warm = made_up_columns(2, quick=True)                       # compiles every kernel of the group (not timed)
    run_columns([simulation_for(s, device, 1) for s in warm])
    sims = [simulation_for(s, device, 1) for s in scenarios]
    wp.synchronize_device(device)
    t0 = time.perf_counter()
    group = run_columns(sims, None, _decided)
    wall = time.perf_counter() - t0
    failed = [f"{k}: {type(r).__name__}: {r}" for k, r in enumerate(group) if isinstance(r, BaseException)]
    out = {"device": device, "columns": n, "particles": sum(s.model.n_particles for s in sims),
           "group": {"wall_s": wall, "cases_per_hour": 3600.0 * n / wall, "classes": _classes(group),
                     "steps": [None if isinstance(r, BaseException) else r.steps for r in group],
                     "failed": failed}}
    rows = []
    for k in range(min(alone, n)):
        if time.time() > deadline:
            break
        sim = simulation_for(scenarios[k], "cpu", 1)
        t0 = time.perf_counter()
        res = sim.run(None, callback=lambda s, frame: _decided(0, s, frame))
        rows.append({"case": k, "wall_s": time.perf_counter() - t0, "class": _classes([res])[0]})
    per_case = sum(r["wall_s"] for r in rows) / len(rows) if rows else None
    out["cpu_alone"] = {"cases": rows, "cases_per_hour_one_core": 3600.0 / per_case if per_case else None}
    out["same_class"] = sum(r["class"] == out["group"]["classes"][r["case"]] for r in rows)
    out["speedup"] = (out["group"]["cases_per_hour"] / out["cpu_alone"]["cases_per_hour_one_core"]
                      if per_case else None)
    return out
