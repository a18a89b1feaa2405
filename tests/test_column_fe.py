"""The static plane-strain FE of a sawn column (mpm_warp.validation.column_fe) against closed forms.

Three exact or classical answers: the overhang's bending moment from statics (exact for any layering), a layered
slender overhang's surface stress from composite-beam theory (exact but for the elasticity correction of a
distributed load, which falls as (h/x)^2), and the overburden normal to the bed in an uncut column.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("scipy")

from mpm_warp.errors import InvalidArgument  # noqa: E402
from mpm_warp.validation.column_fe import solve_column  # noqa: E402

G = 9.81
WEAK = (0.02, 0.2e6, 0.25)                                          # thickness m, E Pa, nu
#: three layers, top to bottom, a stiff crust over soft snow over a harder base (thickness, rho, E, nu)
LAYERED = ((0.04, 250.0, 20e6, 0.25), (0.12, 120.0, 2e6, 0.30), (0.04, 200.0, 8e6, 0.20))


def composite_surface_stress(slab, moment: float) -> float:
    """sigma_xx at the top surface (Pa) of a layered plane-strain beam under ``moment`` (N m/m, top in tension)."""
    faces = np.cumsum([0.0] + [ly[0] for ly in slab])                 # depth of each face
    Ep = np.array([ly[2] / (1.0 - ly[3] ** 2) for ly in slab])
    t, mid = np.diff(faces), 0.5 * (faces[1:] + faces[:-1])
    neutral = np.sum(Ep * t * mid) / np.sum(Ep * t)
    EI = np.sum(Ep * (t**3 / 12.0 + t * (mid - neutral) ** 2))
    return Ep[0] * moment * neutral / EI


def test_overhang_moment_is_statics():
    """Over the cut the slab hangs free: at x from the cut end its moment is q x^2 / 2 and its axial force 0,
    exactly, whatever the layering. Measured: 3e-4 at 0.5 m, 6e-5 at 1 m (the 2 cm mesh)."""
    r = solve_column(LAYERED, WEAK, 4.0, 2.0, dx=0.02)
    q = G * sum(t * rho for t, rho, _, _ in LAYERED)
    for x in (0.5, 1.0, 1.5):
        N, M = r.moment(x)
        assert M == pytest.approx(q * x * x / 2.0, rel=1e-3)
        assert abs(N) < 1e-4 * q * x


def test_layered_overhang_follows_composite_beam():
    """At 1.5 and 2 m from the free end of a 20 cm three-layer overhang (ratios 7.5 and 10 of the depth), the
    crust's surface stress is composite-beam theory's less 0.92 % and 0.52 %: the elasticity correction of a
    distributed load, falling as (h/x)^2 (0.92 / 0.52 = 1.77, (2 / 1.5)^2 = 1.78). Mesh-independent: the same to
    0.01 % on 4, 2 and 1 cm elements (the 2 cm mesh here)."""
    r = solve_column(LAYERED, WEAK, 5.0, 3.0, dx=0.02)
    q = G * sum(t * rho for t, rho, _, _ in LAYERED)
    measured = {}
    for x in (1.5, 2.0):
        top = (np.abs(r.x - x) < 1e-9) & (r.depth < 1e-9)
        measured[x] = r.sigma[top, 0].mean() / composite_surface_stress(LAYERED, q * x * x / 2.0) - 1.0
    assert measured[1.5] == pytest.approx(-0.0093, abs=0.001)
    assert measured[2.0] == pytest.approx(-0.0052, abs=0.001)


def test_uncut_column_carries_its_overburden():
    """Mid-column of an uncut 3 m column on flat ground, sigma_zz is minus the weight above, in every layer
    (measured within 0.22 % of the largest)."""
    r = solve_column(LAYERED, WEAK, 3.0, 0.0, dx=0.02)
    faces = np.cumsum([0.0] + [ly[0] for ly in LAYERED])
    above = np.cumsum([0.0] + [G * t * rho for t, rho, _, _ in LAYERED])
    mid = np.abs(r.x - 1.5) < 0.011
    for k, (_, rho, _, _) in enumerate(LAYERED):
        sel = mid & (r.layer == k)
        exact = -(above[k] + G * rho * (r.depth[sel] - faces[k]))
        assert np.max(np.abs(r.sigma[sel, 1] - exact)) < 3e-3 * above[-1]


@pytest.mark.parametrize("plane, confinement", [("strain", 1.0 / 3.0), ("stress", 0.25)])
def test_weak_layer_on_its_base_is_confined_along_the_bed(plane, confinement):
    """Mid-column of an uncut 3 m column the thin weak layer, bonded to the rigid base, cannot stretch along the
    bed, so its stress along the bed is its normal stress times nu/(1 - nu) in plane strain (no strain across the
    column either) and times nu in plane stress (no stress across it): 1/3 and 1/4 at its nu = 0.25 (measured
    within 0.3 %, at its top, where the slab shears it). The slab above can stretch over the soft layer, and does
    not follow either."""
    r = solve_column(LAYERED, WEAK, 3.0, 0.0, dx=0.02, plane=plane)
    sel = (np.abs(r.x - 1.5) < 0.011) & (r.layer == -1)
    ratio = r.sigma[sel, 0] / r.sigma[sel, 1]
    assert np.max(np.abs(ratio - confinement)) < 5e-3 * confinement


@pytest.mark.slow
def test_sawn_slab_converges_under_refinement():
    """The peak surface stress of 20 cm of 120 kg/m^3 sawn 0.3 m on a 1 MPa weak layer, 2 m column: 1.42 kPa,
    the same to 0.2 % on 1 cm and 5 mm elements, 2.5 cm past the tip on the bedded side. A cantilever clamped at
    the tip would carry 6 (q a^2 / 2) / h^2 = 1.59 kPa there: a cut 1.5 slab depths long is no slender beam."""
    slab = ((0.2, 120.0, 846274.0, 0.3),)
    peaks = []
    for dx in (0.01, 0.005):
        r = solve_column(slab, (0.03, 1e6, 0.3), 2.0, 0.3, dx=dx)
        i = np.argmax(np.where((r.layer == 0) & (r.depth < 1e-9), r.sigma_1, -np.inf))
        peaks.append((r.sigma_1[i], r.x[i]))
    assert peaks[1][0] == pytest.approx(peaks[0][0], rel=0.005)
    assert peaks[1][0] == pytest.approx(1422.0, rel=0.01)
    assert peaks[1][1] == pytest.approx(0.325, abs=0.006)


@pytest.mark.parametrize("kwargs, field", [({"cut": 2.0}, "cut"), ({"slope_angle": 70.0}, "slope_angle"),
                                           ({"column_ends": "plumb"}, "column_ends"), ({"dx": 0.0}, "dx"),
                                           ({"plane": "3d"}, "plane")])
def test_bad_input_names_the_argument(kwargs, field):
    args = {"cut": 0.5, **kwargs}
    cut = args.pop("cut")
    with pytest.raises(InvalidArgument, match=field):
        solve_column(LAYERED, WEAK, 2.0, cut, **args)


@pytest.mark.slow
def test_plumb_ends_on_a_slope_follow_weac():
    """50 cm of 250 kg/m^3 (5 MPa) on a 35 deg slope, 2 m column, sawn 0.6 m: the slab's peak surface stress.
    weac 2.6 (its pst and vpst systems) gives 3.50 / 5.98 kPa for slope-normal / plumb ends cut from upslope and
    5.45 / 3.02 kPa from downslope; the FE 2.99 / 5.35 and 5.61 / 3.27 kPa (1 cm elements, 2 cm kept clear of
    the tip's corner and the end faces): within 15 % of weac, and the same order, which a plumb face sheared
    the wrong way would swap."""
    slab, weak = ((0.5, 250.0, 5e6, 0.25),), (0.03, 1e6, 0.25)
    got = {}
    for ends in ("slope_normal", "vertical"):
        for cut_from in ("upslope", "downslope"):
            r = solve_column(slab, weak, 2.0, 0.6, slope_angle=35.0, cut_from=cut_from, column_ends=ends, dx=0.01)
            clear = ((r.layer >= 0) & (np.hypot(r.x - 0.6, r.depth - 0.5) > 0.02) & (r.from_end_face > 0.02)
                     & (r.from_end_face < 1.98))
            got[ends, cut_from] = r.sigma_1[clear].max()
    assert got["slope_normal", "upslope"] == pytest.approx(2993.0, rel=0.02)
    assert got["vertical", "upslope"] == pytest.approx(5354.0, rel=0.02)
    assert got["slope_normal", "downslope"] == pytest.approx(5613.0, rel=0.02)
    assert got["vertical", "downslope"] == pytest.approx(3272.0, rel=0.02)
