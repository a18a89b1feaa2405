"""Command line: ``mpm-warp run|resume|scenes|info|render|plot|profile|sweep|field ...`` (``field``: .cli_field).

Errors the library raises on purpose (bad input, blow-ups) are printed as one
clear line with exit status 2 (input, files) or 3 (simulation), never a traceback;
so is any other OSError (a file system refusing a write), and a missing optional package
(its name and the extra that installs it, :mod:`mpm_warp.extras`).
The commands call the library: :func:`mpm_warp.run`, :func:`mpm_warp.resume`,
:func:`mpm_warp.post.render.render_run`, :func:`mpm_warp.post.plots.plot_run`,
:func:`mpm_warp.sweep.run_sweep`.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import signal
import sys
import time

from .errors import MPMError, SimulationBlowUp
from .extras import missing_line, missing_module, require
from .stop import Interrupted, StopRequest  # noqa: F401 (Interrupted: part of the CLI's interface)

__all__ = ["main"]


class Progress:
    """Frame callback printing sim time, steps, speed and ETA on one line (stderr)."""

    def __init__(self, end_time: float, stream=sys.stderr, every: float = 0.5, stop: StopRequest | None = None,
                 quiet: bool = False):
        self.stop = stop
        self.quiet = quiet
        self.end = end_time
        self.stream = stream
        self.every = every
        self.t0 = time.perf_counter()
        self.last = 0.0

    def __call__(self, sim, frame: int):
        if self.stop is not None:
            self.stop.frame_done()
            if self.stop.requested:
                return False
        if self.quiet:
            return None
        now = time.perf_counter()
        t = sim.time
        if now - self.last < self.every and t < self.end:
            return None
        self.last = now
        elapsed = now - self.t0
        frac = min(t / self.end, 1.0) if self.end > 0 else 1.0
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("inf")
        steps = int(sim.state.steps.numpy()[0])
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        self.stream.write(f"\r[{bar}] t = {t:.4g}/{self.end:.4g} s  frame {frame}  steps {steps}  "
                          f"elapsed {elapsed:.1f} s  ETA {eta:.1f} s ")
        self.stream.flush()
        return None

    def close(self):
        if not self.quiet:
            self.stream.write("\n")


class _StderrLines(logging.Handler):
    """The library's warnings (e.g. a stale lock taken over) as ``mpm-warp: ...`` lines on the current stderr."""

    def emit(self, record):
        sys.stderr.write(f"mpm-warp: {record.getMessage()}\n")


def _summary(res, out=None):
    out = out or sys.stdout
    out.write(
        f"done: {res.frames} frames, {res.steps} steps, t = {res.sim_time:.6g} s, {res.n_particles} particles on "
        f"{res.device}; stepping {res.wall_time:.2f} s ({res.particle_steps_per_s / 1e6:.2f} M particle-steps/s)"
        + (f"; {res.edge_hits} particle clamps at the grid edge" if res.edge_hits else "")
        + (f"; {res.inversions} inversions (det F_tr <= 0) and {res.floor_events} singular-value floor events"
           if res.inversions or res.floor_events else "")
        + (f"\noutput: {res.output}" if res.output else "") + "\n")
    from .field.probability import probability_line

    sr = dict(res.scene_result)
    oc, weac = sr.pop("outcome", None), sr.pop("weac", None)
    if oc is not None:
        where = (f", the slab broke {oc['slab_fracture_at']:.2f} m from the cut end" if oc["class"] == "SF" else
                 f", the crack stopped {oc['arrest_at']:.2f} m from the cut end" if oc["class"] == "ARR" else "")
        out.write(f"  field: {oc['field_line']}{where}" + (f" ({oc['note']})" if oc.get("note") else "") + "\n")
        out.write(probability_line(oc))
    if weac is not None:
        if weac.get("weac") is None:
            out.write(f"  weac: {weac['note']}\n")
        else:
            a_c = weac["critical_cut"]
            out.write(f"  weac {weac['weac']}: critical cut " + (f"{a_c:.3f} m" if a_c is not None else "none")
                      + f" (G = G_c = w_f = {weac['G_c']:.3g} J/m^2); G = {weac['energy_release_rate']:.3g} J/m^2 "
                      f"at the cut of {weac['cut']:.3g} m\n")
    for k, v in sr.items():
        out.write(f"  {k}: {_short(v)}\n")


def _short(v) -> str:
    """A scene result's value for the summary: numbers with 4 digits, long series by their length (--json has all)."""
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, (list, tuple)):
        return f"[{', '.join(_short(x) for x in v)}]" if len(v) <= 8 else f"({len(v)} values; --json prints them)"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k}: {_short(x)}" for k, x in v.items()) + "}"
    return str(v)


def _stopped(res, path) -> int:
    where = f"; frames so far are in {path}, resume with `mpm-warp resume {path}`" if path else ""
    print(f"mpm-warp: stopped at t = {res.sim_time:.6g} s on request{where}", file=sys.stderr)
    return 130


def cmd_run(a) -> int:
    from .runner import run

    with StopRequest() as stop:
        prog = Progress(math.inf, stream=sys.stderr, stop=stop, quiet=a.quiet)

        def start(sim):
            prog.end = sim.scenario.time.end
            stop.attach(sim)

        try:
            res = run(a.scenario, a.out, a.device, a.set, overwrite=a.overwrite, max_memory=a.max_memory,
                      on_start=start, callback=prog)
        finally:
            prog.close()
    _summary(res)
    if res.stopped:
        return _stopped(res, a.out)
    if a.json:
        print(json.dumps({k: v for k, v in res.__dict__.items() if k != "monitors"}, default=str))
    if a.plot and a.out:
        from .post.plots import plot_run

        for f in plot_run(a.out, None):
            print(f)
    elif a.plot:
        print("mpm-warp: --plot needs --out (a run file to plot)", file=sys.stderr)
    return 0


def cmd_profile(a) -> int:
    from .field import FieldCase, field_case
    from .scenes.profile import read_profile

    data = read_profile(a.file)
    print(data.summary())
    for rec in data.pst_tests:
        case = field_case(data, rec, calibrate=not a.no_calibration)
        print(f"  {case.test}: " + (_case_line(case) if isinstance(case, FieldCase) else f"not set up: {case.message}"))
    return 0


def _case_line(case) -> str:
    """A set-up field case in one line, with its notes below it."""
    wf, p = case.fracture_energy, case.params
    if wf.value is not None:
        w = (f"the weak layer's fracture energy this test implies: {wf.value:.3g} J/m^2 (weac's G at the cut; G_I "
             f"{wf.G_I:.2g}, G_II {wf.G_II:.2g}; weak layer E {p.weak_layer.E / 1e6:g} MPa, nu {p.weak_layer.nu:g}, "
             f"cut from {p.saw.cut_from}, {p.column_ends.replace('_', '-')} ends)")
    else:
        w = f"no fracture energy read back ({wf.reason}); runs with the default {p.weak_layer.w_f:g} J/m^2"
    from .scenes.profile.column import describe

    notes = "".join(f"\n      note: {n}" for n in case.notes)
    return f"{describe(case.column)}; {w}{notes}"


def cmd_resume(a) -> int:
    from .runner import resume

    with StopRequest() as stop:
        prog = Progress(math.inf, stream=sys.stderr, stop=stop, quiet=a.quiet)

        def start(sim):
            prog.end = a.end if a.end is not None else sim.scenario.time.end
            stop.attach(sim)
            steps = int(sim.state.steps.numpy()[0])
            print(f"mpm-warp: resuming {a.run} after frame {sim.frame_index}, at t = {sim.time:.6g} s (step {steps}), "
                  f"to t = {prog.end:.6g} s", file=sys.stderr)

        try:
            res = resume(a.run, device=a.device, end_time=a.end, callback=prog, max_memory=a.max_memory,
                         on_start=start)
        finally:
            prog.close()
    _summary(res)
    return _stopped(res, a.run) if res.stopped else 0


def cmd_scenes(a) -> int:
    from .loader import list_scenes, load_scenario
    from .scenes import SCENES

    for name in list_scenes():
        print(f"{name:20s} {load_scenario(name).description}")
    print("\nscene kinds ([scene] kind = ...):")
    for kind, st in SCENES.items():
        print(f"{kind:20s} {st.description}")
    return 0


def cmd_info(a) -> int:
    from .result import versions

    print(json.dumps(versions(), indent=1))
    return 0


def cmd_render(a) -> int:
    from .io import check_output_dir
    from .post.render import render_run

    if a.out is not None:
        check_output_dir(a.out)

    out = render_run(a.run, field=a.field, frames=a.frames, out_dir=a.out, video=a.video or False,
                     size=tuple(a.size), camera=a.camera, fps=a.fps)
    print(f"{len(out.pngs)} frames of {out.field} [{out.unit}], colour range {out.clim[0]:.4g} .. "
          f"{out.clim[1]:.4g}, in {os.path.dirname(out.pngs[0]) or '.'}")
    if out.video:
        print(f"film: {out.video}")
    return 0


def cmd_plot(a) -> int:
    from .io import check_output_dir
    from .post.plots import plot_run

    if a.out is not None:
        check_output_dir(a.out)

    files = plot_run(a.run, a.out)
    for f in files:
        print(f)
    if not files:
        print("no plottable series in this run")
    return 0


def cmd_sweep(a) -> int:
    """``mpm-warp sweep``: exit status 0 when every run is ok, 1 when some failed."""
    from .sweep import parse_vary, run_sweep

    res = run_sweep(a.scenario, parse_vary(a.vary), a.cases,
                    a.out or f"sweep-{os.path.splitext(os.path.basename(a.scenario))[0]}", overrides=a.set,
                    scheduler=a.scheduler, n_workers=a.workers, device=a.device, retries=a.retries,
                    plot_x=a.plot_x, plot_y=a.plot_y, progress=not a.quiet)
    for r in res.failed:
        print(f"failed {r['id']}: {r['error']}", file=sys.stderr)
    print(f"sweep: {len(res.rows)} runs, {len(res.rows) - len(res.failed)} ok ({res.skipped} from earlier "
          f"sweeps), {len(res.failed)} failed\nsummary: {res.path}" + (f"\nfigure: {res.figure}" if res.figure else ""))
    return 1 if res.failed else 0


SWEEP_DESCRIPTION = (
    "Run a parameter sweep: the cartesian product of the --vary lists, crossed with the rows of a --cases CSV "
    "file, of scenario overrides (dotted keys as for --set: time.end, materials.snow.E, blocks.0.lo; a key of the "
    "scene table may drop its 'scene.' prefix, e.g. slope_angle for scene.slope_angle). Each case is one run, "
    "executed as a Dask task on a local cluster (one worker per GPU, else per CPU core) or on an existing one "
    "(--scheduler). The runs, their JSON records, summary.csv and summary.png go to --out; running the same "
    "sweep again skips the finished runs.")
SWEEP_EXAMPLE = "example: mpm-warp sweep pst_demo --vary scene.slope_angle=0,10,20,30 --workers 2 --out sweep-slope"


def _add_render(sub) -> None:
    from .post.fields import FIELDS
    from .post.render import CAMERAS

    r = sub.add_parser("render", help="render a run's particles to PNG frames (and a film), off screen")
    r.add_argument("run", help="HDF5 run file")
    r.add_argument("--field", default="collapse", choices=sorted(FIELDS),
                   help="colour: " + "; ".join(f"{f.name} [{f.unit}]" for f in FIELDS.values())
                        + " (definitions and reference states: mpm_warp.post.fields)")
    r.add_argument("--frames", default="all", help="'all' (default), indices '0,10,-1' or a slice '0:50:5'")
    r.add_argument("--out", default=None, help="output folder (default: RUN_render beside the run)")
    r.add_argument("--video", nargs="?", const="gif", default=None, choices=["gif", "mp4"],
                   help="also make a film (default gif; mp4 needs ffmpeg)")
    r.add_argument("--size", nargs=2, type=int, default=[1280, 720], metavar=("W", "H"), help="pixels")
    r.add_argument("--camera", default="auto", choices=CAMERAS, help="side (PSTs), oblique, auto")
    r.add_argument("--fps", type=float, default=10.0, help="film frames per second")
    r.set_defaults(func=cmd_render)


def _add_sweep(sub) -> None:
    p = sub.add_parser("sweep", help="run a parameter sweep on a Dask cluster (one run per case)",
                       description=SWEEP_DESCRIPTION, epilog=SWEEP_EXAMPLE)
    p.add_argument("scenario", help="scenario file or ready scene name")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="values of one override; the sweep is the cartesian product of every --vary")
    p.add_argument("--cases", metavar="CSV", help="cases file: a header of override keys, one case per row")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override for every case")
    p.add_argument("--out", help="folder of the runs and the summary (default sweep-SCENARIO)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="existing Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--workers", type=int, help="workers of the local cluster (default: one per GPU, else core)")
    p.add_argument("--device", help="cpu | cuda | cuda:N (default: each worker's GPU, else the CPU)")
    p.add_argument("--retries", type=int, default=2, help="extra attempts of a run whose worker died")
    p.add_argument("--plot-x", help="parameter on the figure's x axis (default: the first varied)")
    p.add_argument("--plot-y", help="summary column on the y axis (default: the first numeric scene result)")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_sweep)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    p = argparse.ArgumentParser(prog="mpm-warp", description="MPM in NVIDIA Warp for anticrack propagation in snow")
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run a scenario file or a ready scene")
    r.add_argument("scenario", help="path to a .toml scenario, or the name of a ready scene (see `mpm-warp scenes`)")
    r.add_argument("--out", default=None, help="HDF5 output file (default: no output)")
    r.add_argument("--device", default=None,
                   help="cpu | cuda | cuda:N (default: MPM_WARP_DEVICE, then CUDA if present)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set time.end=0.5 --set materials.slab.E=2e6")
    r.add_argument("--overwrite", action="store_true",
                   help="replace an existing --out (never the scenario itself nor a non-regular file)")
    r.add_argument("--max-memory", default=None, metavar="SIZE",
                   help="refuse a scene whose memory estimate exceeds SIZE, e.g. 16G (the machine's available "
                        "memory is always a limit)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--json", action="store_true", help="print the run summary as JSON")
    r.add_argument("--plot", action="store_true", help="then plot the run (as `mpm-warp plot`; needs --out)")
    r.set_defaults(func=cmd_run)

    rs = sub.add_parser("resume", help="continue a run from its last checkpoint")
    rs.add_argument("run", help="the run's HDF5 file (its checkpoint RUN.ckpt.h5 must sit beside it)")
    rs.add_argument("--device", default=None, help="as for run (default: MPM_WARP_DEVICE, then CUDA if present)")
    rs.add_argument("--end", type=float, default=None, help="new end time (s), after the run file's last frame")
    rs.add_argument("--max-memory", default=None, metavar="SIZE", help="as for run")
    rs.add_argument("--quiet", action="store_true", help="no progress bar")
    rs.set_defaults(func=cmd_resume)

    sc = sub.add_parser("scenes", help="list the ready scenes and the scene kinds, one line each")
    sc.set_defaults(func=cmd_scenes)
    info = sub.add_parser("info", help="versions")
    info.set_defaults(func=cmd_info)
    _add_render(sub)
    pl = sub.add_parser("plot", help="plot a run's series (front speed, markers, shear test, energy)")
    pl.add_argument("run", help="HDF5 run file")
    pl.add_argument("--out", default=None, help="output folder (default: RUN_plots beside the run)")
    pl.set_defaults(func=cmd_plot)
    pr = sub.add_parser("profile", help="read a CAAML snow profile: its layers, densities, and each PST as a column "
                                   "or the reason it cannot be one")
    pr.add_argument("file", help="a CAAML 5 or 6 XML snow profile")
    pr.add_argument("--no-calibration", action="store_true",
                    help="set up each PST's column without calibrating its weak layer (faster; a column the "
                         "calibration would refuse is then not found)")
    pr.set_defaults(func=cmd_profile)
    _add_sweep(sub)
    from .cli_field import add_field

    add_field(sub)
    return p


def main(argv=None) -> int:
    """Entry point of the ``mpm-warp`` command."""
    args = build_parser().parse_args(argv)
    log = logging.getLogger("mpm_warp")
    if not any(isinstance(h, _StderrLines) for h in log.handlers):
        log.addHandler(_StderrLines())
        log.propagate = False
    try:
        require(args.command)
        return args.func(args)
    except SimulationBlowUp as e:
        print(f"mpm-warp: {e}", file=sys.stderr)
        return 3
    except (MPMError, ModuleNotFoundError) as e:      # a missing optional package: its name and its extra
        module = missing_module(e)
        if module is None and not isinstance(e, MPMError):
            raise
        print(missing_line(args.command, module) if module else f"mpm-warp: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:                 # a file system refusing something the checks could not foresee
        print(f"mpm-warp: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        signum = getattr(e, "signum", signal.SIGINT)
        print(f"mpm-warp: interrupted ({signal.Signals(signum).name}); complete frames are kept in the output file",
              file=sys.stderr)
        return 128 + signum


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
