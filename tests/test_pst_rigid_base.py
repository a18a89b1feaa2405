"""A PST on a rigid base (``scene.rigid_base``): the weak layer bonded to the bed, no substratum.

The settled column against the oedometric closed form: under the overburden ``q`` of the slab and the weak
layer, a laterally confined layer of thickness ``t`` and constrained modulus ``M = E (1 - nu) / ((1 + nu)
(1 - 2 nu))`` shortens by ``q t / M``. On a rigid base only the weak layer shortens; an elastic substratum
adds its own shortening, ``(q d + rho g d^2 / 2) / M`` (its own weight too).
"""

import dataclasses

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.config import TimeControl
from mpm_warp.scenes.pst import PSTParams
from mpm_warp.scenes.pst.build import build

#: a short uncut column: 20 cm of slab on a 4 cm weak layer (4 cells), 15 cm of substratum unless rigid
COLUMN = PSTParams(dx=0.01, length=0.6, slab_thickness=0.2, weak_layer_thickness=0.04, margin=0.05)
COLUMN = dataclasses.replace(COLUMN, saw=dataclasses.replace(COLUMN.saw, cut_length=0.0))
G = 9.81


def _constrained(E, nu):
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def _settled_slab_base(p: PSTParams) -> float:
    """Vertical displacement (m) of the slab's lowest particle row in the middle third, settled (0.15 s)."""
    sim = mw.Simulation(build(p, TimeControl(end=0.15, frame_interval=0.15)), device="cpu")
    sim.step_to(0.15)
    s = sim.group_state("slab")
    x, x0 = s.x.numpy(), np.asarray(s.x0)
    mid = (x0[:, 0] > p.length / 3) & (x0[:, 0] < 2 * p.length / 3)
    row = mid & (x0[:, 1] < x0[mid, 1].min() + 1e-6)
    return float((x - x0)[row, 1].mean())


@pytest.fixture(scope="module")
def settled():
    return {rigid: _settled_slab_base(dataclasses.replace(COLUMN, rigid_base=rigid)) for rigid in (False, True)}


def test_a_rigid_base_leaves_out_the_substratum():
    p = dataclasses.replace(COLUMN, rigid_base=True)
    sc = build(p, TimeControl(end=0.1, frame_interval=0.1))
    assert [b.name for b in sc.blocks] == ["weak_layer", "slab"]
    assert p.substratum_depth == 0.0 and p.base_y == pytest.approx(0.04)
    assert sc.walls[0].kind == "sticky" and sc.walls[0].point[1] == 0.0       # the weak layer lies on the bed


@pytest.mark.slow
def test_on_a_rigid_base_the_slab_settles_by_the_weak_layer_alone(settled):
    """Measured -16.5 um against -16.3 um (+1.1 %); a bed that let the layer's base move would add to it."""
    p = COLUMN
    q = G * (p.slab.density * p.slab_thickness + p.weak_layer.density * p.weak_layer_thickness)
    weak = q * p.weak_layer_thickness / _constrained(p.weak_layer.E, p.weak_layer.nu)
    assert -settled[True] == pytest.approx(weak, rel=0.05)


@pytest.mark.slow
def test_the_substratum_adds_its_own_shortening(settled):
    """Elastic substratum minus rigid base: measured 17.3 um against the closed form's 16.3 um (+5.6 %)."""
    p = COLUMN
    q = G * (p.slab.density * p.slab_thickness + p.weak_layer.density * p.weak_layer_thickness)
    d, s = p.substratum_thickness, p.substratum
    sub = (q * d + s.density * G * d * d / 2.0) / _constrained(s.E, s.nu)
    assert settled[True] - settled[False] == pytest.approx(sub, rel=0.10)


@pytest.mark.parametrize("change, field, needle", [
    ({"rigid_base": "yes"}, "scene.rigid_base", "true or false"),
    ({"bed": "slip"}, "scene.bed", "'sticky'"),
    ({"substratum_thickness": 0.3}, "scene.substratum_thickness", "no substratum"),
])
def test_a_rigid_base_refuses_what_contradicts_it(change, field, needle):
    with pytest.raises(mw.InvalidArgument) as e:
        dataclasses.replace(COLUMN, **{"rigid_base": True, **change}).validate()
    assert e.value.field == field and needle in str(e.value) and "\n" not in str(e.value)


def test_the_key_round_trips_and_stays_out_of_files_without_it():
    assert "rigid_base" not in COLUMN.to_dict()
    d = dataclasses.replace(COLUMN, rigid_base=True).to_dict()
    assert d["rigid_base"] is True
