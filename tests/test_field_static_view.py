"""weac's static view of a field case (mpm_warp.field.static_view): the numbers of the three paths it replaced, and
one static solve per case however many parts of the batch read it."""

from __future__ import annotations

import pytest

from mpm_warp.field.batch import _tasks, gather
from mpm_warp.field.fracture_energy import implied_fracture_energy
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.static_rule import weac_static_rule
from mpm_warp.field.static_view import clear_static_views, static_view
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.density_laws import sigrist_tensile_strength
from mpm_warp.scenes.pst.static import static_column

#: made-up columns: w_f given (flat), read back from the cut (steep), a long cut with the default w_f (long)
TABLE = """id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends
flat,End,0,40,12,15,180,4,,0.3,
steep,SF,30,60,20,25,220,3,,,vertical
long,SF,35,150,100,20,120,3,,,
"""

#: what the three paths before the view gave (weac 2.6.4): G, G_I, G_II at the cut (J/m^2), the critical cut (m)
#: at the case's w_f, the slab's peak stress over strength (-) and the static class
KNOWN = {
    "flat": (0.02519835604588865, 0.024045053039712175, 0.0011533030061764737, 0.2391979401540496,
             0.13409089823727713, "END"),
    "steep": (0.06639791034746037, 0.04975852888935785, 0.016639381458102516, 0.20000000000000956,
              0.20856151139547274, "END"),
    "long": (13.559638872590629, 5.678453113687095, 7.881185758903533, 0.45825249134135376, 10.112588701564995,
             "SF"),
}


@pytest.fixture
def cases(tmp_path):
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    clear_static_views()
    found, refused = gather([str(table)], calibrate=False)
    assert refused == [] and [c.pit for c in found] == [f"psts.csv#{k}" for k in KNOWN]
    return found


def _old_paths(p):
    """The three computations as fracture_energy.py, batch._static_cut and static_rule.py made them before."""
    col = static_column(p)
    strengths = [ly.tensile_strength if ly.tensile_strength > 0 else sigrist_tensile_strength(ly.density)
                 for ly in p.slab_stack()]
    return (*wr.energy_release_rate(col, float(p.saw.cut_length)), wr.critical_cut(col, p.weak_layer.w_f),
            float(wr.slab_stress(col, float(p.saw.cut_length), strengths, dx=0.01, dz=0.005)["peak_ratio"]))


def test_the_view_gives_the_numbers_of_the_three_paths_it_replaced(cases):
    for c in cases:
        v = static_view(c.params)
        got = (v.G, v.G_I, v.G_II, v.critical_cut, v.peak_ratio)
        assert got == _old_paths(c.params)                                  # the same solves, bit for bit
        assert got == pytest.approx(KNOWN[c.pit.split("#")[1]][:5], rel=1e-9)
        assert v.static_class == KNOWN[c.pit.split("#")[1]][5]
        assert weac_static_rule(c.params) == {"class": v.static_class, "peak_ratio": v.peak_ratio}
        assert v.cut == c.record.cut_length and v.w_f == c.params.weak_layer.w_f and v.unavailable is None
    flat, steep, long = cases
    assert flat.params.weak_layer.w_f == 0.3                                # given: G is not read back
    assert steep.fracture_energy.value == steep.fracture_energy.G == static_view(steep.params).G
    assert static_view(steep.params).critical_cut == pytest.approx(0.20, rel=1e-12)   # G(a_c) = G(cut): a_c = cut
    assert long.fracture_energy.G is None and long.params.weak_layer.w_f == 0.79    # a long cut: the default w_f


def test_one_static_solve_per_case_for_the_set_up_the_pre_cut_and_the_static_rule(tmp_path, monkeypatch):
    calls = {"energy_release_rate": 0, "critical_cut": 0, "slab_stress": 0}
    for name in calls:
        def counted(*a, _f=getattr(wr, name), _n=name, **kw):
            calls[_n] += 1
            return _f(*a, **kw)
        monkeypatch.setattr(wr, name, counted)
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    clear_static_views()
    found, _ = gather([str(table)], calibrate=False)                     # the set-up: G of the cases read back
    assert calls == {"energy_release_rate": 1, "critical_cut": 0, "slab_stress": 0}
    tasks = _tasks(found, str(tmp_path), FieldProtocol(), "cpu", [])    # the pre-cut and the static rule
    assert [t["static_class"] for t in tasks] == [k[5] for k in KNOWN.values()]
    for c in found:                                                       # every later reader: no new solve
        weac_static_rule(c.params)
        implied_fracture_energy(c.params, c.record.cut_length)
    assert calls == {"energy_release_rate": 3, "critical_cut": 3, "slab_stress": 3}
    assert [t["scenario"].scene.saw.pre_cut for t in tasks] == pytest.approx(
        [0.5 * k[3] for k in KNOWN.values()], rel=1e-12)                  # half the critical cut
