#!/usr/bin/env bash
# One command for a CUDA machine (see benchmarks/perf/device_suite.py): device tests, graph against eager,
# throughput beside Taichi at ~1M/4M particles, bytes per particle, one production flat PST, a small field batch.
# Usage: bash benchmarks/device_suite.sh [--device cuda:0] [--quick] [--out DIR] [--parts ...]
# Python: $PYTHON, else the repository's .venv, else python3.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
py="${PYTHON:-}"
if [[ -z "$py" ]]; then
  if [[ -x "$here/../.venv/bin/python" ]]; then py="$here/../.venv/bin/python"; else py=python3; fi
fi
export PYTHONUNBUFFERED=1
exec "$py" "$here/perf/device_suite.py" "$@"
