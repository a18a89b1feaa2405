"""How long do the README's own commands take on a fresh clone: the install and main job, and the tests?

Clones the committed checkout (``git clone``: committed files only, as CI sees them) into a temporary folder,
with an empty Warp kernel cache, and runs the README's commands there exactly as written, each ``&&`` part
timed on its own: the main job's (``python3 -m venv``, ``pip install -e .``, ``mpm-warp run pst_demo ...
--plot``) and, with ``--tests``, the test command (the same as ``.ci/run``). The run file gives the
particles, steps and frames of the main job, hence its particle-steps per second. On the plain install,
``mpm-warp field`` on a one-row table must say in one line that it needs the field extra (exit 2).

Writes ``benchmarks/perf/results/fresh_clone.json``. Quote it from a quiet machine: its environment record
holds the load average at the start and the end. Packages come from whatever index pip is configured with
(here a local mirror), so the install time is the machine's, not a download's.

Usage: ``python benchmarks/perf/fresh_clone.py [--tests] [--quick]`` (``--quick`` shortens the main job to
``time.end=0.02``; about 4 min for the full main job here, 10-12 min more with ``--tests``).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time

import h5py

from mpm_warp.studies.environment import environment, git_commit, write_json
from mpm_warp.studies.fresh_clone import FIELD_TABLE, plain_field_verdict, readme_commands, split_parts
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
RESULTS = os.path.join(HERE, "results")


def run_parts(command: str, cwd: str, env: dict, log) -> list[dict]:
    """Run ``command``'s ``&&`` parts one after the other in ``cwd``; wall time and exit status of each."""
    parts = []
    for part in split_parts(command):
        t0 = time.perf_counter()
        rc = subprocess.run(["bash", "-c", part], cwd=cwd, env=env, stdout=log, stderr=subprocess.STDOUT).returncode
        parts.append({"command": part, "wall_s": round(time.perf_counter() - t0, 2), "rc": rc})
        print(f"  {parts[-1]['wall_s']:8.1f} s  rc {rc}  {part}", flush=True)
        if rc != 0:
            break
    return parts


def run_file_counts(path: str) -> dict:
    """Particles, steps and frames of the main job's run file."""
    with h5py.File(path, "r") as f:
        steps = int(f["step"][-1])
        return {"n_particles": int(f.attrs["n_particles"]), "steps": steps, "frames": int(f["step"].shape[0])}


def field_on_plain_install(clone: str, env: dict) -> dict:
    """``mpm-warp field`` on a one-row table in the clone's venv (the plain install), judged."""
    table = os.path.join(clone, "field_check.csv")
    with open(table, "w") as fh:
        fh.write(FIELD_TABLE)
    p = subprocess.run([os.path.join(".venv", "bin", "mpm-warp"), "field", table, "--out", "field_check"], cwd=clone,
                       env=env, capture_output=True, text=True)
    verdict = plain_field_verdict(p.returncode, p.stderr)
    print(f"  plain install, mpm-warp field: rc {p.returncode}, {'ok' if verdict['ok'] else 'NOT ok'}", flush=True)
    return verdict


def main(argv=None) -> int:
    ap = parser(__doc__, "the main job to time.end=0.02")
    ap.add_argument("--tests", action="store_true", help="also time the README's test command")
    ap.add_argument("--keep", action="store_true", help="keep the clone (its path is printed)")
    args = ap.parse_args(argv)
    with open(os.path.join(ROOT, "README.md")) as fh:
        commands = readme_commands(fh.read())
    if args.quick:
        commands["main_job"] = commands["main_job"].replace("--plot", "--plot --set time.end=0.02")
    work = tempfile.mkdtemp(prefix="mpm_warp_fresh_")
    clone = os.path.join(work, "mpm_warp")
    subprocess.run(["git", "clone", "-q", "--no-hardlinks", ROOT, clone], check=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("VIRTUAL_ENV", "MPM_WARP", "PYTHON"))}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if ".venv" not in p)
    env["WARP_CACHE_PATH"] = os.path.join(work, "warp_cache")      # a fresh machine compiles every kernel
    data = {"environment": environment("cpu"), "commit": git_commit(clone), "readme_commands": commands,
            "warp_cache": "empty at the start (a fresh machine compiles every kernel)"}
    print(f"fresh clone in {clone}", flush=True)
    with open(os.path.join(work, "log.txt"), "w") as log:
        data["main_job"] = {"parts": run_parts(commands["main_job"], clone, env, log)}
        h5 = os.path.join(clone, "pst_demo.h5")
        if os.path.exists(h5):
            data["main_job"].update(run_file_counts(h5))
            data["main_job"]["pictures"] = sorted(os.listdir(os.path.join(clone, "pst_demo_plots")))
        if os.path.exists(os.path.join(clone, ".venv", "bin", "mpm-warp")):
            data["field_plain_install"] = field_on_plain_install(clone, env)
        if args.tests:
            shutil.rmtree(os.path.join(clone, ".venv"))                # the test command makes its own venv
            data["tests"] = {"parts": run_parts(commands["tests"], clone, env, log)}
    data["ok"] = all(p["rc"] == 0 for k in ("main_job", "tests") if k in data for p in data[k]["parts"]) and \
        data.get("field_plain_install", {}).get("ok", True)
    name = "fresh_clone" + ("_quick" if args.quick else "")
    print(write_json(name, data, out_dir(args, RESULTS, "fresh_clone")))
    if args.keep:
        print(f"kept: {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    return 0 if data["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
