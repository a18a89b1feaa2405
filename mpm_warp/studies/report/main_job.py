"""The main job's section and README block: the README's own commands timed on a fresh clone."""

from __future__ import annotations

from .core import Context, section
from .fmt import count, env_note, environment_of, finite, fx, secs, table
from .pages import ref

__all__ = ["BEGIN", "END", "SOURCE", "main_job_block"]

BEGIN = "<!-- main-job:begin -->"
END = "<!-- main-job:end -->"
SOURCE = "perf/results/fresh_clone.json"
TITLE = "The main job"


def _part(parts: list[dict], word: str) -> dict | None:
    return next((p for p in parts if word in p["command"]), None)


def _rate(job: dict) -> float | None:
    run = _part(job["parts"], "mpm-warp run")
    if run is None or not all(finite(job.get(k)) for k in ("n_particles", "steps")):
        return None
    return job["n_particles"] * job["steps"] / run["wall_s"]


def _command(data: dict) -> str:
    return "python benchmarks/perf/fresh_clone.py" + (" --tests" if "tests" in data else "")


@section("perf", TITLE, SOURCE, _command,
         question="How long do the README's own commands take on a fresh clone: the install and the main job, "
                  "and the tests?")
def render_main_job(data: dict, ctx) -> list[str]:
    rows = []
    for key, what in (("main_job", "install and run the main job"), ("tests", "install and run the tests")):
        for p in (data.get(key) or {}).get("parts", []):
            rows.append([what, f"`{p['command']}`", secs(p["wall_s"]), p["rc"]])
    out = ["A `git clone` of the committed checkout, an empty Warp kernel cache (every kernel compiles, as on a "
           "new machine), each `&&` part of the README's commands timed on its own. Packages come from the index pip "
           "is configured with (here a local mirror: the install time is the machine's, not a download's).",
           ""] + table(["command", "part", "wall time", "exit status"], rows)
    job = data.get("main_job") or {}
    rate = _rate(job)
    if rate is not None:
        out += ["", f"The main job: {count(job['n_particles'])} particles, {count(job['steps'])} steps, "
                f"{count(job.get('frames'))} frames, {fx(rate, 1, 1e-6)} M particle-steps/s over the run's wall time "
                f"(compiling and pictures included); it wrote {', '.join(f'`{p}`' for p in job.get('pictures', []))}."]
    return out + ["", env_note(data)]


def main_job_block(ctx: Context) -> list[str] | None:
    """The README's lines on the main job's time, or None when the fresh-clone timing is not committed."""
    data = ctx.load(SOURCE)
    if data is None or not data.get("ok"):
        return None
    parts = data["main_job"]["parts"]
    install = sum(p["wall_s"] for p in parts if "mpm-warp run" not in p["command"])
    run = _part(parts, "mpm-warp run")
    tests = sum(p["wall_s"] for p in (data.get("tests") or {}).get("parts", []))
    env = environment_of(data)
    line = (f"Measured from a fresh clone on a {env['cpu_count']}-core CPU ({env['date']}; the machine's load is in "
            f"the linked section): the install "
            f"took {secs(install)}, the run with its pictures {secs(run['wall_s'])}")
    if tests:
        line += f"; the test command below {secs(tests)}"
    return [line + f" ({ref(TITLE, '.')})."]
