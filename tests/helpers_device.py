"""The one device switch of the test suite.

``MPM_WARP_TEST_DEVICE`` (default ``"cpu"``) names the Warp device the
device-meaningful test modules run on; ``benchmarks/perf/device_suite.py`` sets it
to ``"cuda:0"`` on a GPU machine. ``MPM_WARP_TEST_DETERMINISTIC=1`` switches
Warp's atomics to its run-to-run deterministic mode (set by ``conftest.py``
before any kernel module exists): tests that compare two runs bit for bit
(resume, graph batching) need it on CUDA, where float atomic adds land in a
different order every run. On the CPU a launch runs on one thread and the
switch changes nothing.
"""

from __future__ import annotations

import os

#: Warp device of the device-parametrised tests.
DEVICE = os.environ.get("MPM_WARP_TEST_DEVICE", "cpu")

#: Whether Warp's deterministic atomics were requested for this test session.
DETERMINISTIC = os.environ.get("MPM_WARP_TEST_DETERMINISTIC", "0") not in ("", "0")


def configure_warp() -> None:
    """Apply the deterministic-atomics switch to ``warp.config`` (before kernels are built)."""
    if DETERMINISTIC:
        import warp as wp

        wp.config.deterministic = wp.DeterministicMode.RUN_TO_RUN
