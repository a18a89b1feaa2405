"""The free-end fit of the shear test's peaks (``mpm_warp.studies.shear_rows.length_fit``): ``peak = a - b / L``."""

import numpy as np
import pytest

from mpm_warp.studies.shear_rows import length_fit


def test_fit_recovers_an_exact_free_end_law():
    """Peaks of an endless sample at 0.99 of tau_p less 21 mm of unloaded sample: a and b back to round-off."""
    L = np.array([0.3, 0.6, 1.2])
    f = length_fit(L, 0.99 - 0.021 / L)
    assert f["a"] == pytest.approx(0.99, abs=1e-12) and f["b"] == pytest.approx(0.021, abs=1e-12)
    assert f["max_residual"] < 1e-12


def test_fit_residual_is_the_largest_miss():
    """Three points off the law by +-0.001: the fit's largest residual says so (between 0.0005 and 0.002)."""
    L = np.array([0.3, 0.6, 1.2])
    f = length_fit(L, 0.99 - 0.021 / L + np.array([0.001, -0.001, 0.001]))
    assert 5e-4 < f["max_residual"] < 2e-3
    assert f["a"] == pytest.approx(0.99, abs=3e-3)
