"""Command line: ``mpm-warp run|resume|scenes|info ...``.

Errors the library raises on purpose (bad input, blow-ups) are printed as one
clear line with exit status 2 (input) or 3 (simulation), never a traceback.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time

from .errors import MPMError, SimulationBlowUp

__all__ = ["main"]


class StopRequest:
    """SIGINT/SIGTERM handler that asks the run to stop at the next frame boundary.

    Python may swallow a KeyboardInterrupt raised inside a callback, so the CLI
    catches the signals itself; the run then ends after a complete frame and
    says where its output and checkpoint are. A second signal aborts at once.
    """

    def __init__(self):
        self.requested = False
        self._old = {}

    def __enter__(self):
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)

    def _handle(self, signum, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True
        sys.stderr.write("\nmpm-warp: stop requested; finishing the current frame (signal again to abort)\n")


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
        if self.stop is not None and self.stop.requested:
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


def _summary(res, out=sys.stdout):
    out.write(
        f"done: {res.frames} frames, {res.steps} steps, t = {res.sim_time:.6g} s, {res.n_particles} particles on "
        f"{res.device}; stepping {res.wall_time:.2f} s ({res.particle_steps_per_s / 1e6:.2f} M particle-steps/s)"
        + (f"; {res.edge_hits} particle clamps at the grid edge" if res.edge_hits else "")
        + (f"\noutput: {res.output}" if res.output else "") + "\n")
    for k, v in res.scene_result.items():
        out.write(f"  {k}: {v}\n")


def cmd_run(a) -> int:
    from .loader import load_scenario
    from .runner import simulation_for

    sc = load_scenario(a.scenario, a.set)
    sim = simulation_for(sc, device=a.device)
    with StopRequest() as stop:
        prog = Progress(sc.time.end, stop=stop, quiet=a.quiet)
        try:
            res = sim.run(a.out, callback=prog)
        finally:
            prog.close()
    _summary(res)
    if stop.requested:
        where = f"; frames so far are in {a.out}, resume with `mpm-warp resume {a.out}`" if a.out else ""
        print(f"mpm-warp: stopped at t = {res.sim_time:.6g} s on request{where}", file=sys.stderr)
        return 130
    if a.json:
        print(json.dumps({k: v for k, v in res.__dict__.items() if k != "monitors"}, default=str))
    return 0


def cmd_resume(a) -> int:
    from .runner import resume

    res = resume(a.run, device=a.device, end_time=a.end)
    _summary(res)
    return 0


def cmd_scenes(a) -> int:
    from .loader import list_scenes, load_scenario

    for name in list_scenes():
        print(f"{name:20s} {load_scenario(name).description}")
    return 0


def cmd_info(a) -> int:
    from .result import versions

    print(json.dumps(versions(), indent=1))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (extended by the render, plot and sweep commands)."""
    p = argparse.ArgumentParser(prog="mpm-warp", description="MPM in NVIDIA Warp for anticrack propagation in snow")
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run a scenario file or a ready scene")
    r.add_argument("scenario", help="path to a .toml scenario, or the name of a ready scene (see `mpm-warp scenes`)")
    r.add_argument("--out", default=None, help="HDF5 output file (default: no output)")
    r.add_argument("--device", default=None,
                   help="cpu | cuda | cuda:N (default: MPM_WARP_DEVICE, then CUDA if present)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set time.end=0.5 --set materials.slab.E=2e6")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--json", action="store_true", help="print the run summary as JSON")
    r.set_defaults(func=cmd_run)

    rs = sub.add_parser("resume", help="continue a run from its last checkpoint")
    rs.add_argument("run", help="the run's HDF5 file (its checkpoint RUN.ckpt.h5 must sit beside it)")
    rs.add_argument("--device", default=None)
    rs.add_argument("--end", type=float, default=None, help="new end time (s)")
    rs.set_defaults(func=cmd_resume)

    sc = sub.add_parser("scenes", help="list the ready scenes")
    sc.set_defaults(func=cmd_scenes)
    info = sub.add_parser("info", help="versions")
    info.set_defaults(func=cmd_info)

    for mod in ("render", "plots", "sweep"):
        try:
            m = __import__(f"mpm_warp.{mod}", fromlist=["add_cli"])
        except ImportError:
            continue
        if hasattr(m, "add_cli"):
            m.add_cli(sub)
    return p


def main(argv=None) -> int:
    """Entry point of the ``mpm-warp`` command."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except SimulationBlowUp as e:
        print(f"mpm-warp: {e}", file=sys.stderr)
        return 3
    except MPMError as e:
        print(f"mpm-warp: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("mpm-warp: interrupted; complete frames are kept in the output file", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
