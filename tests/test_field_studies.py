"""The field studies' shared code (mpm_warp.field.studies): the draws of the committed batches' cases, the slab's
strength what-ifs and the readers of a run's slab stress."""

from __future__ import annotations

import json
import os
import random
from types import SimpleNamespace

import numpy as np
import pytest

from mpm_warp.field.cases import FieldCase, FieldRefusal
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.studies.drawn import aligned_records, committed_batches, draw_rows, pit_file
from mpm_warp.scenes.pst import PSTParams
from mpm_warp.scenes.snowpack import SnowLayer

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "benchmarks", "field", "results")


def _row(k: int, observed: str, wall: float | None = 10.0, status: str = "ok") -> dict:
    return {"id": f"pit{k}-0-{k:012x}", "test": f"PST {k}/100 (End) down 30 cm", "observed": observed,
            "status": status, "wall_s": wall, "predicted": "END", "runaway_cut": 0.2, "setup": "4 cells"}


def test_the_draw_samples_each_observed_class_among_the_cheap_finished_cases(tmp_path):
    rows = ([_row(k, "END") for k in range(6)] + [_row(10 + k, "SF") for k in range(3)]
            + [_row(20, "ARR"), _row(21, "ARR", wall=500.0), _row(22, "ARR", status="failed"), _row(23, "SF", None)])
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps({"cases": rows[:5]}))
    b.write_text(json.dumps({"cases": rows[3:]}))            # rows 3 and 4 in both: one case each
    chosen, pool = draw_rows([str(a), str(b)], 2, 7, 120.0)
    assert pool == 10                                         # 6 END, 3 SF, 1 ARR: not the slow, failed or untimed
    assert [c["observed"] for c in chosen] == ["END", "END", "SF", "SF", "ARR"]
    # the sample is random.Random(seed).sample of each class in turn (END, SF, ARR), over the rows sorted by id
    rng = random.Random(7)
    ends = sorted((r for r in rows[:6]), key=lambda r: r["id"])
    sfs = sorted((r for r in rows[6:9]), key=lambda r: r["id"])
    want = rng.sample(ends, 2) + rng.sample(sfs, 2) + rng.sample([rows[9]], 1)
    assert [c["id"] for c in chosen] == [c["id"] for c in want]
    assert draw_rows([str(a), str(b)], 2, 7, 120.0)[0] == chosen         # the same seed, the same draw
    assert draw_rows([str(a), str(b)], 9, 0, 5.0) == ([], 0)              # none cheap enough


def test_a_batch_id_names_its_pit_and_the_committed_batches_are_found():
    assert pit_file("snowpits-55737-caaml-117-c47b87b1731a") == "snowpits-55737-caaml.xml"
    assert all(os.path.exists(b) for b in committed_batches(RESULTS))


def _field_case(params: PSTParams, pit: str = "p.xml") -> FieldCase:
    """A field case of ``params`` without a pit's record (what the studies read of it is its params)."""
    return FieldCase(pit, "PST 1/2 (End) down 3 cm", "End", None, params, None, None, ())


def test_the_records_of_a_rerun_line_up_with_its_cases_and_refusals():
    from mpm_warp.field.batch import case_digest

    proto = FieldProtocol().validate()
    case, other = _field_case(PSTParams()), _field_case(PSTParams(length=1.5))
    digest = case_digest(case, proto)
    batch = SimpleNamespace(records=[{"id": f"p-0-{digest}", "status": "ok"}],
                            refused=[FieldRefusal("p.xml", "PST 1/2 (End) down 3 cm", "budget", "too large")])
    refusal = FieldRefusal("q.xml", "PST 2/2 (SF) down 1 cm", "calibration", "too soft")
    out = aligned_records([refusal, case, other], batch, proto)
    assert out == [{"id": None, "status": "refused", "error": "too soft"}, {"id": f"p-0-{digest}", "status": "ok"},
                   {"id": None, "status": "refused", "error": "too large"}]


def test_a_weaker_slab_scales_every_layer_or_the_faceted_ones_alone():
    from mpm_warp.field.studies.slab_strength import faceted_share, weaker

    layers = (SnowLayer(0.1, 150.0, name="FCxr 4F"), SnowLayer(0.3, 250.0, name="RGsr 1F"))
    c = _field_case(PSTParams(slab_layers=layers))
    assert faceted_share(c.params) == pytest.approx(0.25)
    law = [ly.strength for ly in c.params.slab_stack()]
    assert [ly.strength for ly in weaker(c, 0.5).params.slab_stack()] == pytest.approx([0.5 * s for s in law])
    assert [ly.strength for ly in weaker(c, 1.0, 0.5).params.slab_stack()] == pytest.approx([0.5 * law[0], law[1]])
    assert [ly.strength for ly in weaker(c, 0.5, 0.5).params.slab_stack()] == pytest.approx([0.25 * law[0],
                                                                                             0.5 * law[1]])
    # the law's strength, now given to each layer: the same values
    assert [ly.tensile_strength for ly in weaker(c, 1.0).params.slab_stack()] == pytest.approx(law)


def test_the_slab_stress_readers_give_the_onset_and_the_peaks():
    from mpm_warp.field.studies.slab_fe import run_layers_to
    from mpm_warp.field.studies.slab_stress import mpm_ratio_to, onset_cut, principal_2d

    s = np.zeros((2, 3, 3))
    s[0, 0, 0], s[0, 1, 1] = 3.0, 1.0             # principal 3
    s[1, 0, 1] = s[1, 1, 0] = 2.0                 # pure shear: principal 2
    assert principal_2d(s) == pytest.approx([3.0, 2.0])
    series = {"saw": [0.0, 0.1, 0.2, 0.3], "front": [0.0, 0.105, 0.23, 0.4], "ratio": [[0.1, 0.2], [0.3, 0.1],
                                                                                         [0.2, 0.5], [0.9, 0.1]]}
    assert onset_cut(series, 0.01) == 0.2         # the front 3 cells ahead of the blade (2 needed)
    assert onset_cut(series, 0.1) is None
    assert mpm_ratio_to(series, 0.1) == 0.3 and mpm_ratio_to(series, -1.0) is None
    assert run_layers_to({"series": series}, 0.2) == [0.3, 0.5]
    assert run_layers_to({"series": series}, 0.2, last=True) == [0.2, 0.5]
    assert run_layers_to({"series": series}, None) is None


def test_the_readings_at_the_call_are_the_last_frame_and_the_peaks():
    from mpm_warp.errors import InvalidArgument
    from mpm_warp.field.studies.at_call import AT_CALL_KEYS, readings_at_call

    nan = float("nan")
    series = {"front": [nan, 0.2, 0.5, 0.8], "deflection_front": [nan, 0.0, 0.1, 0.2],
              "marker0_uy": [0.0, -1e-4, -5e-4, -9e-4], "marker1_uy": [0.0, 0.0, -1e-4, -3e-4],
              "marker1_ux": [0.0, 0.0, -1e-2, -1e-2], "slab_stress_ratio": [0.1, 0.4, 0.3, 0.35],
              "slab_crack_cover": [0.0, 0.0, 0.05, 0.02]}
    r = readings_at_call(series, 4.5e-3)
    assert set(r) == set(AT_CALL_KEYS)
    assert r["slab_drop_at_call"] == pytest.approx(0.2)           # 0.9 mm of 4.5 mm at the last frame
    assert r["slab_down_share"] == pytest.approx(0.25)            # 0.2 m of 0.8 m cracked
    assert r["slab_stress_ratio"] == pytest.approx(0.4)           # the peak, not the last frame
    assert r["slab_crack_cover"] == pytest.approx(0.05)
    # a deflection front ahead of the damage front (end zone lift) counts the whole crack; a run without one: None
    assert readings_at_call({"front": [0.5], "deflection_front": [0.7]}, 4.5e-3)["slab_down_share"] == 1.0
    assert readings_at_call({"marker0_uy": [-1e-3]}, 4.5e-3)["slab_down_share"] is None
    with pytest.raises(InvalidArgument, match="collapse_height"):
        readings_at_call(series, 0.0)
