"""The CPU step flushes subnormal numbers to zero on its own threads and leaves the caller's mode as it was
(kernels/fpmode.py)."""

import platform

import numpy as np
import pytest
import warp as wp

from mpm_warp.studies.blocks import block_simulation

pytestmark = pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"),
                                reason="FTZ/DAZ are x86-64 bits; elsewhere the kernels are no-ops")


@wp.kernel
def _tiny_product(a: wp.array(dtype=wp.float32), out: wp.array(dtype=wp.float32)):
    out[0] = a[0] * a[1]


def _product() -> float:
    """1e-20 * 1e-20 in float32 on the calling thread: 1e-40 (subnormal) normally, 0 with FTZ."""
    a = wp.array(np.array([1e-20, 1e-20], dtype=np.float32), device="cpu")
    out = wp.zeros(1, dtype=wp.float32, device="cpu")
    wp.launch(_tiny_product, 1, inputs=[a, out], device="cpu")
    return float(out.numpy()[0])


@pytest.mark.parametrize("threads", [1, 2])
def test_step_flushes_on_its_threads_only(threads):
    assert _product() == pytest.approx(1e-40, rel=1e-2)  # the caller's mode: subnormals kept
    sim = block_simulation(2, "elastic", 64, "cpu", threads)
    st = sim.stepper
    st.set_frame_end(1e9)
    st.steps(3)
    assert _product() == pytest.approx(1e-40, rel=1e-2)  # put back after the steps
    with st.flushed(0):
        assert _product() == 0.0
    assert _product() == pytest.approx(1e-40, rel=1e-2)
    assert int(sim.state.steps.numpy()[0]) == 3
