"""The equivalent weak layer (mpm_warp.field.equivalent_layer): a thin layer over the budget runs as a thicker one with
the same fracture energy, strength, collapse height and stiffness per unit area."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math

import pytest

from mpm_warp.field.batch import case_digest, gather
from mpm_warp.field.equivalent_layer import (
    MAX_GEOMETRY_ERROR,
    equivalent_layer,
    equivalent_params,
    equivalent_weak_layer,
    thinnest_layer,
)
from mpm_warp.field.protocol import (
    FieldProtocol,
    particle_estimate,
    protocol_column,
    protocol_equivalent,
    protocol_params,
)
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.pst import PSTParams
from mpm_warp.scenes.pst.params import CRACK_BAND_CELLS
from mpm_warp.scenes.snowpack import SnowLayer
from mpm_warp.scenes.weak_layer import WeakLayer

HEAD = "id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends\n"
#: a 1 cm weak layer under a 40 cm slab, 150 cm long: 221,400 particles at 3 cells, over today's budget
THIN = "thin,End,0,150,40,40,200,1,,0.5,\n"
#: the same layer under the 25 cm slab of a 1 m column: fits at 3 cells (about 96,000 particles)
FITS = "fits,End,0,100,30,25,200,1,,0.5,\n"


def test_the_equivalent_layer_by_hand():
    layer = WeakLayer()                       # E 1 MPa, tau_p 1 kPa, w_f 0.79 J/m^2, h_c from weac's fit
    eq = equivalent_weak_layer(layer, 0.01, 0.03)
    assert eq.E == pytest.approx(3.0e6)       # E t_eq / t: the same E/t, 100 MPa/m
    assert eq.E / 0.03 == pytest.approx(layer.E / 0.01)
    assert eq.h_c == pytest.approx(4.70e-3 * (1.0 - math.exp(-10.0 / 7.78)))   # the 1 cm layer's: 3.400 mm
    assert eq.h_c == pytest.approx(3.4001e-3, abs=1e-7)
    assert (eq.w_f, eq.tau_p, eq.nu, eq.density, eq.M, eq.beta) == (0.79, 1000.0, 0.3, 150.0, 1.2, 0.3)
    assert eq.p0_floor_ratio * eq.E == pytest.approx(layer.p0_floor_ratio * layer.E)   # the same floor, in Pa
    assert equivalent_weak_layer(dataclasses.replace(layer, h_c=2e-3), 0.01, 0.03).h_c == 2e-3   # a given one kept
    with pytest.raises(ValueError, match="xi"):
        equivalent_weak_layer(dataclasses.replace(layer, xi=0.01), 0.01, 0.03)


def test_the_calibrated_equivalent_layer_keeps_strength_energy_and_collapse():
    p = PSTParams(weak_layer_thickness=0.01, rigid_base=True, substratum_layers=())
    real, eq = p.calibrated(), equivalent_params(p, 0.03).calibrated()
    assert eq.tau_p == pytest.approx(real.tau_p, rel=1e-6)
    assert eq.h_c == pytest.approx(real.h_c, rel=1e-6)
    assert eq.w_f == pytest.approx(real.w_f, rel=2e-3)          # the fit's own tolerance on both
    assert eq.delta_s == pytest.approx(real.delta_s, rel=5e-3)


def test_the_thinnest_layer_the_budget_allows_by_hand():
    """On a rigid base, ``L (h + t) / (t / (cells ppc))^2 = N``: a quadratic in t."""
    p = protocol_column(PSTParams(length=1.5, slab_thickness=0.4, weak_layer_thickness=0.01), FieldProtocol())
    L, h, N = 1.5, p.slab_depth, 120_000
    for cells in (4, 3):
        k2 = (cells * p.particles_per_cell) ** 2
        a = N / k2
        t = (L + math.sqrt(L * L + 4.0 * a * L * h)) / (2.0 * a)
        got = thinnest_layer(p, cells, N)
        assert t <= got < t + 1.1e-4                 # rounded up to 0.1 mm
        assert particle_estimate(dataclasses.replace(equivalent_params(p, got), dx=got / cells)) <= N


def test_on_old_snow_the_extra_thickness_comes_out_of_the_old_snow():
    p = PSTParams(weak_layer_thickness=0.01, substratum_layers=(SnowLayer(0.02, 250.0), SnowLayer(0.2, 300.0)))
    q = equivalent_params(p, 0.04)
    assert q.base_y == pytest.approx(p.base_y) and q.slab_depth == p.slab_depth
    assert [ly.thickness for ly in q.substratum_layers] == pytest.approx([0.19])     # the 2 cm layer gone, 1 cm off
    r = equivalent_params(PSTParams(weak_layer_thickness=0.01), 0.03)
    assert r.substratum_thickness == pytest.approx(0.13) and r.base_y == pytest.approx(0.16)


@pytest.mark.skipif(wr.weac_unavailable() is not None, reason="weac is not installed")
@pytest.mark.parametrize("slab, t, t_eq", [((0.35, 200.0, 5.0e6, 0.25), 0.0087, 0.0171),
                                          ((0.47, 250.0, 1.0e7, 0.25), 0.0039, 0.0199),
                                          ((0.25, 180.0, 3.0e6, 0.25), 0.01, 0.03)])
def test_weac_critical_cut_of_the_real_and_the_equivalent_column(slab, t, t_eq):
    """weac's bed of springs has the same stiffness per unit area; only the layer's lever arm (h + t)/2 about the
    slab's mid-plane moves, by (t_eq - t)/(h + t) of itself: the bound on the cut's relative change (first order)."""
    real = wr.StaticColumn(slab=(slab,), weak_layer_thickness=t, weak_layer_E=1.0e6, weak_layer_nu=0.3, length=1.5)
    eq = dataclasses.replace(real, weak_layer_thickness=t_eq, weak_layer_E=1.0e6 * t_eq / t)
    a, b = wr.critical_cut(real, 0.5), wr.critical_cut(eq, 0.5)
    bound = (t_eq - t) / (slab[0] + t)
    assert bound <= MAX_GEOMETRY_ERROR
    assert a is not None and abs(b - a) / a <= bound


@pytest.fixture
def table(tmp_path):
    path = tmp_path / "psts.csv"
    path.write_text(HEAD + THIN + FITS)
    return str(path)


def test_a_thin_layer_over_the_budget_runs_with_the_equivalent_layer(table):
    thin, fits = gather([table], calibrate=False)[0]
    proto = FieldProtocol()
    rigid = protocol_column(thin.params, proto)
    assert particle_estimate(dataclasses.replace(rigid, dx=0.01 / 3)) > proto.max_particles   # refused before
    p, tc, note = protocol_params(thin.params, proto)
    eq = protocol_equivalent(thin.params, proto)
    assert p is not None and eq.cells == 4 and eq.equivalent_thickness == pytest.approx(0.0183)
    # by hand: 1875 t^2 - 1.5 t - 0.6 = 0 at 4 cells of 2 particles (120,000 / 8^2 = 1875), t = 18.29 mm
    assert note.startswith("equivalent weak layer 1.83 cm for 1.00 cm (E 1.83 MPa for 1 MPa, collapse height "
                           "3.40 mm kept), 4 cells across the weak layer, dx 4.5")
    assert p.weak_layer_thickness == eq.equivalent_thickness and p.slab_depth == thin.params.slab_depth
    assert p.weak_layer.E == pytest.approx(1.83e6) and p.weak_layer.w_f == 0.5
    assert particle_estimate(p) <= proto.max_particles
    assert p.calibrated().h_c == pytest.approx(thin.params.calibrated().h_c, rel=1e-6)
    # a column that fits at 3 cells keeps its own layer, and its key
    pf, _, nf = protocol_params(fits.params, proto)
    assert protocol_equivalent(fits.params, proto) is None and pf.weak_layer_thickness == pytest.approx(0.01)
    assert nf.startswith("3 cells across the weak layer")
    old = {"case": fits.params.to_dict(), "protocol": proto.run_key(), "crack_band_cells": CRACK_BAND_CELLS}
    assert case_digest(fits, proto) == hashlib.sha256(json.dumps(old, sort_keys=True, default=str).encode()
                                                      ).hexdigest()[:12]
    # the equivalent case's key names its equivalence
    plain = {"case": thin.params.to_dict(), "protocol": proto.run_key(), "crack_band_cells": CRACK_BAND_CELLS}
    assert case_digest(thin, proto) != hashlib.sha256(json.dumps(plain, sort_keys=True, default=str).encode()
                                                      ).hexdigest()[:12]


def test_a_column_still_too_large_is_refused(table):
    thin = gather([table], calibrate=False)[0][0]
    proto = FieldProtocol(max_particles=5000)
    p, tc, why = protocol_params(thin.params, proto)
    assert p is None and tc is None
    assert why.startswith("the column is too large for the per-case budget: 221,400 particles at the coarsest grid "
                          "the weak layer allows (3 cells), above 5,000; no equivalent weak layer fits either")
    assert isinstance(equivalent_layer(protocol_column(thin.params, proto), (4, 3), 5000), str)
