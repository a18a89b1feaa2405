"""The field batch (mpm_warp.field.batch, ``mpm-warp field``): tables in, scores out, a killed batch resumes."""

from __future__ import annotations

import json
import os

import pytest

from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.field.batch import finished_records, gather, run_field, score_records
from mpm_warp.field.probability import weibull_break_probability
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.scores import baseline_majority, scores
from mpm_warp.field.table import table_profiles

TABLE = """id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends
tiny-a,End,0,40,12,15,180,4,,0.3,
tiny-b,Arr,0,40,15,15,180,4,,0.5,vertical
no-slope,End,,100,30,30,200,3,,,
"""


@pytest.fixture
def cases(tmp_path):
    """The cases of :data:`TABLE`, set up without calibrating (a test of the set-up and the protocol runs none)."""
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    return gather([str(table)], calibrate=False)[0]


def test_recall_balanced_accuracy_and_the_majority_baseline():
    obs = ["END"] * 6 + ["SF"] * 2 + ["ARR"] * 2
    pred = ["END"] * 5 + ["SF"] + ["END", "SF"] + ["ARR", "NP"]
    s = scores(obs, pred)
    assert s["recall"] == {"END": 5 / 6, "SF": 0.5, "ARR": 0.5}
    assert s["balanced_accuracy"] == pytest.approx((5 / 6 + 0.5 + 0.5) / 3)
    assert s["accuracy"] == pytest.approx(0.7)
    assert s["confusion"]["columns"] == ["END", "SF", "ARR", "NP"]
    assert s["confusion"]["counts"] == [[5, 1, 0, 0], [1, 1, 0, 0], [0, 0, 1, 1]]
    # always the majority class: recall 1 for it, 0 for the others, balanced accuracy 1/3
    assert scores(obs, baseline_majority(obs))["balanced_accuracy"] == pytest.approx(1 / 3)
    assert scores([], [])["balanced_accuracy"] is None


def test_a_table_row_becomes_a_profile_or_one_line(tmp_path):
    path = tmp_path / "psts.csv"
    path.write_text(TABLE)
    rows = table_profiles(path)
    a, b, bad = rows
    assert a.refusal is None and a.record.field_line() == "PST 12/40 (End) down 15 cm" and a.w_f == 0.3
    assert [ly.thickness for ly in a.profile.layers] == [0.15, 0.04] and a.profile.slope_angle == 0.0
    assert b.profile.country == "US"                           # vertical ends, as the row asks
    assert bad.profile is None
    assert bad.refusal == ("psts.csv: row 4 (no-slope): slope_deg is empty (required: a slope in [0, 60] deg (the "
                           "model takes slopes of 0-60 deg))")
    (tmp_path / "broken.csv").write_text("id,outcome\nx,End\n")
    with pytest.raises(ValueError, match="columns slope_deg, column_cm, cut_cm, weak_layer_cm are missing"):
        table_profiles(tmp_path / "broken.csv")


@pytest.mark.slow
def test_a_killed_batch_resumes_without_rerunning_its_finished_cases(tmp_path):
    """The first run stops after one case (as a kill would); the second keeps that case's files untouched and runs
    the other on the 2 threads its protocol asks for."""
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    out = str(tmp_path / "out")
    first = run_field([str(table)], out, workers=1, limit=1, progress=False)
    (rec,) = first.records
    assert rec["status"] == "ok" and first.skipped == 0
    # what the stopped batch has measured, read back without running the other case
    cases, _ = gather([str(table)], calibrate=False)
    assert len(cases) == 2 and finished_records(cases, out) == [rec]
    done = os.path.join(out, rec["id"] + ".json")
    stamp = os.stat(done).st_mtime_ns
    again = run_field([str(table)], out, workers=1, progress=False, protocol=FieldProtocol(threads=2))
    assert [r["threads"] for r in again.records] == [1, 2]     # what each case's step ran on
    assert [r["workers"] for r in again.records] == [1, 1]     # and how many cases ran side by side
    assert again.skipped == 1 and len(again.records) == 2 and os.stat(done).st_mtime_ns == stamp
    assert all(r["status"] == "ok" for r in again.records)
    assert [r["observed"] for r in again.records] == ["END", "ARR"]
    assert [r["w_f_source"] for r in again.records] == ["given", "given"]     # the table's w_f, not read back
    assert all(r["predicted"] in ("END", "SF", "ARR", "NP", "running") for r in again.records)
    # each record carries the slab's peak stress over its strength, the model's probabilities from it, weac's peak
    # ratio at the recorded cut and the information bar's numbers (the 12 cm cut of a 40 cm column: 0.3)
    for r in again.records:
        assert r["slab_peak_stress_ratio"] > 0.0 and r["static_peak_ratio"] > 0.0
        # the slab's body (its rows the grid does not tie to the weak layer) carries no more than the whole slab
        assert 0.0 < r["slab_peak_body_stress_ratio"] <= r["slab_peak_stress_ratio"]
        assert r["p_sf"] == pytest.approx(weibull_break_probability(min(r["slab_peak_body_stress_ratio"], 1.0)))
        assert r["p_end"] + r["p_sf"] + r["p_arr"] == pytest.approx(1.0)
        assert r["slab_depth"] == pytest.approx(0.15) and r["slab_density"] == pytest.approx(180.0)
    assert again.records[0]["cut_share"] == pytest.approx(0.3)
    # the files a reader gets: the cases, the refusals, the scores of the model and its baselines, the figure
    with open(os.path.join(out, "scores.json")) as fh:
        sc = json.load(fh)
    assert sc["cases"] == 2 and set(sc) >= {"model", "majority", "weac_static", "wall_s", "forecast"}
    assert set(sc["forecast"]) >= {"model", "climatology", "majority", "weac_static"}
    assert "cross-validate" in sc["forecast_missing"]["information_bar"]      # one pit, one case a class
    assert sc == json.loads(json.dumps(score_records(again.records)))
    assert [(g["threads"], g["workers"], g["cases"]) for g in sc["wall_s_by_config"]] == [(1, 1, 1), (2, 1, 1)]
    assert sc["wall_s_by_config"][1]["median"] == again.records[1]["wall_s"]
    with open(os.path.join(out, "refused.csv")) as fh:
        assert "slope_deg is empty" in fh.read()
    assert os.path.getsize(os.path.join(out, "confusion.png")) > 0
    # the batch's calibration of the model's readings, fitted on its two cases (END, ARR), applied by a batch under
    # the same protocol (here the same folder again, every case resumed); another protocol's batch refuses it
    from mpm_warp.field.calibration_file import apply_calibration, read_calibration

    cal_path = os.path.join(out, "calibration.json")
    cal = read_calibration(cal_path, FieldProtocol(threads=2).run_key())
    assert cal["trained_on"] == {"END": 1, "SF": 0, "ARR": 1}
    applied = run_field([str(table)], out, workers=1, progress=False, protocol=FieldProtocol(threads=2),
                        calibration=cal_path)
    assert applied.skipped == 2
    assert applied.scores["forecast"]["calibrated_from_file"]["rps"] == pytest.approx(
        score_records(again.records, calibration=cal)["forecast"]["calibrated_from_file"]["rps"])
    assert apply_calibration(cal, again.records).shape == (2, 3)
    with pytest.raises(InvalidArgument, match="max_particles differ"):
        run_field([str(table)], str(tmp_path / "other"), workers=1, progress=False, calibration=cal_path,
                  protocol=FieldProtocol(max_particles=20_000))
    assert not os.path.exists(tmp_path / "other")                    # refused before the batch made its folder
    # a finished case run on past its call, on a copy: the batch's files stay as they were
    from mpm_warp.field.run_on import run_on

    case = again.records[1]
    run_file = os.path.join(out, case["id"] + ".h5")
    before = os.stat(run_file).st_mtime_ns
    went = run_on(out, case["id"], str(tmp_path / "on"), after=0.01)
    assert os.stat(run_file).st_mtime_ns == before
    assert went["sim_time_after"] == pytest.approx(0.01, abs=0.006)       # to the frame at or past 0.01 s
    assert went["peak_stress_ratio_before"] == pytest.approx(case["slab_peak_stress_ratio"])
    # the slab's body at the call, from the final checkpoint: with no rows left out it is the whole slab's reading
    # at the last frame; leaving out the rows the grid ties to the weak layer can only lower it; no body, None
    import h5py

    from mpm_warp.field.run_on import scenario_of
    from mpm_warp.field.studies.at_call import body_stress_ratio, case_readings

    sc = scenario_of(out, case["id"])
    with h5py.File(run_file, "r") as f:
        last = float(f["scalars"]["slab_stress_ratio"][-1])
        last_body = float(f["scalars"]["slab_body_stress_ratio"][-1])
    assert body_stress_ratio(out, case["id"], sc, tie_cells=-1.0) == pytest.approx(last, rel=1e-6)
    body = case_readings(out, case["id"], sc)["slab_body_stress_ratio_at_call"]
    assert body == pytest.approx(last_body, rel=1e-6) and 0.0 < body <= last     # the monitor's, at the last frame
    # each record carries the model's readings the calibrated forecast reads: the run's from its files, the closed
    # forms from its column as recorded, the same a record from before them gets where it is scored
    from mpm_warp.field.calibrated import MODEL_READINGS, RUN_READINGS, closed_form_readings, run_readings

    for r, c in zip(again.records, cases, strict=True):
        assert set(MODEL_READINGS) <= set(r)
        assert {k: r[k] for k in closed_form_readings(c.params)} == closed_form_readings(c.params)
        ran = run_readings(out, r["id"], scenario_of(out, r["id"]))
        assert set(ran) == {"run_slab_crack_ratio", *RUN_READINGS} and {k: r[k] for k in ran} == ran
    assert case["run_slab_body_stress_ratio"] == body and case["run_slab_drop_at_call"] >= 0.0
    older = {k: v for k, v in case.items() if k not in MODEL_READINGS or k == "static_peak_ratio"}
    with open(os.path.join(out, case["id"] + ".json"), "w") as fh:   # a record written before the readings
        json.dump(older, fh)
    (back,) = [r for r in finished_records(cases, out) if r["id"] == case["id"]]
    assert {k: back[k] for k in MODEL_READINGS} == {k: case[k] for k in MODEL_READINGS}
    assert body_stress_ratio(out, case["id"], sc, tie_cells=100.0) is None       # 15 cm of slab: no body
    # a damaged checkpoint: the run's readings are None and the record says where, the case still counts
    ck = os.path.join(out, case["id"] + ".ckpt.h5")
    with open(ck, "r+b") as fh:
        fh.truncate(100)
    (hurt,) = [r for r in finished_records(cases, out) if r["id"] == case["id"]]
    assert hurt["status"] == "ok" and all(hurt[k] is None for k in ("run_slab_crack_ratio", *RUN_READINGS))
    assert hurt["touchdown_distance"] == case["touchdown_distance"]           # the closed forms need no file
    assert case["id"] + ".ckpt.h5" in hurt["readings_note"] and out in hurt["readings_note"]


def test_bad_batch_arguments_are_one_line(tmp_path, capsys):
    assert main(["field", str(tmp_path / "nothing-here"), "--out", str(tmp_path / "o")]) == 2
    assert "INPUT = " in capsys.readouterr().err
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    assert main(["field", str(table), "--out", str(tmp_path / "o"), "--workers", "0"]) == 2
    assert "workers = 0 is invalid: expected an integer >= 1" in capsys.readouterr().err
    assert main(["field", str(table), "--out", str(tmp_path / "o"), "--threads", "0"]) == 2
    assert "threads = 0 is invalid" in capsys.readouterr().err
    assert main(["field", str(table), "--out", str(tmp_path / "o"), "--pre-cut-share", "2"]) == 2
    assert "pre_cut_share = 2" in capsys.readouterr().err


def test_the_bootstrap_intervals_of_a_balanced_accuracy():
    """A perfect predictor against the majority: no spread; one right half the time on 40 cases a class: the
    spread of a mean of three binomial recalls, sqrt(p (1 - p) / (3 n)) = 0.0456, about 0.18 wide at 95 %."""
    from mpm_warp.field.uncertainty import balanced_accuracy_intervals

    obs = ["END"] * 40 + ["SF"] * 40 + ["ARR"] * 40
    half = [o if k % 2 else "NP" for k, o in enumerate(obs)]
    u = balanced_accuracy_intervals(obs, {"model": obs, "majority": baseline_majority(obs), "half": half},
                                    reference="model")
    assert u["intervals"]["model"] == [1.0, 1.0] and u["intervals"]["majority"] == pytest.approx([1 / 3, 1 / 3])
    assert u["differences"]["majority"]["value"] == pytest.approx(2 / 3)
    assert u["differences"]["majority"]["interval"] == pytest.approx([2 / 3, 2 / 3])
    assert u["differences"]["majority"]["share_above"] == 1.0
    lo, hi = u["intervals"]["half"]
    assert lo < 0.5 < hi and hi - lo == pytest.approx(2 * 1.96 * (0.25 / 120) ** 0.5, rel=0.15)
    # paired: the difference to itself is nothing, and the same seed gives the same intervals
    same = balanced_accuracy_intervals(obs, {"model": half, "copy": half}, reference="model")
    assert same["differences"]["copy"]["interval"] == [0.0, 0.0]
    assert balanced_accuracy_intervals(obs, {"model": half}, reference="model") == \
        balanced_accuracy_intervals(obs, {"model": half}, reference="model")
    with pytest.raises(ValueError, match="reference 'x' is not one of the predictors"):
        balanced_accuracy_intervals(obs, {"model": half}, reference="x")


def test_the_protocol_runs_the_weak_layer_on_a_rigid_base_and_keys_its_cache_by_it(cases):
    """weac reads the fracture energy back on a rigid base; the run uses the same column unless asked not to, and a
    batch's cached cases are reused only under the protocol that ran them (threads aside)."""
    from mpm_warp.field.batch import _case_id
    from mpm_warp.field.protocol import protocol_params

    rigid, _, note = protocol_params(cases[0].params, FieldProtocol())
    assert rigid.rigid_base and rigid.substratum_stack() == () and rigid.base_y == pytest.approx(0.04)
    assert note.endswith(", on a rigid base") and "about 3,041 particles" in note   # 0.4 m x 0.19 m at 5 mm
    old, _, note = protocol_params(cases[0].params, FieldProtocol(rigid_base=False))
    assert not old.rigid_base and old.substratum_depth > 0.1 and "rigid" not in note
    ids = {_case_id(cases[0], 0, FieldProtocol(**kw)) for kw in ({}, {"threads": 2}, {"rigid_base": False})}
    assert len(ids) == 2
    with pytest.raises(Exception, match="rigid_base = 1"):
        FieldProtocol(rigid_base=1).validate()


def test_a_protocol_with_the_interface_closure_runs_it_and_keeps_the_keys_of_cases_run_without(cases):
    """The closure is a scene option the protocol passes on; off, the key is the one cases had before the option
    existed (a batch resumes them), on, a key of its own."""
    from mpm_warp.field.batch import case_digest
    from mpm_warp.field.protocol import protocol_params

    closed = FieldProtocol(interface_closure=True)
    p, _, note = protocol_params(cases[0].params, closed)
    assert p.interface_closure and p.rigid_base and note.endswith(", on a rigid base, laminate closure")
    assert not protocol_params(cases[0].params, FieldProtocol())[0].interface_closure
    assert "interface_closure" not in FieldProtocol().run_key()
    assert closed.run_key() == {**FieldProtocol().run_key(), "interface_closure": True}
    assert case_digest(cases[0], closed) != case_digest(cases[0], FieldProtocol())
    with pytest.raises(Exception, match="interface_closure = 1"):
        FieldProtocol(interface_closure=1).validate()


def test_a_protocol_with_a_pre_cut_starts_each_column_sawn_a_share_of_weacs_critical_cut(cases):
    from mpm_warp.field.batch import _case_id
    from mpm_warp.field.protocol import protocol_params

    half = FieldProtocol(pre_cut_share=0.5)
    p, tc, note = protocol_params(cases[0].params, half, static_cut=0.2)
    assert p.saw.pre_cut == pytest.approx(0.1) and note.endswith(", pre-cut 10.0 cm")
    assert tc.end == pytest.approx(p.saw_start + (0.4 - 0.1) / 1.0 + 0.3)    # the saw's way from the pre-cut
    assert protocol_params(cases[0].params, half, static_cut=None)[0].saw.pre_cut == 0.0   # not critical: none
    assert protocol_params(cases[0].params, half, static_cut=2.0)[0].saw.pre_cut == pytest.approx(0.2)  # half L
    assert half == FieldProtocol()                                          # the default
    assert _case_id(cases[0], 0, half) != _case_id(cases[0], 0, FieldProtocol(pre_cut_share=0.0))
    with pytest.raises(Exception, match="pre_cut_share = 1"):
        FieldProtocol(pre_cut_share=1.0).validate()


def test_the_pre_cut_is_measured_on_weacs_critical_cut_of_the_column(cases):
    """The cut at which weac's energy release rate of the column reaches the case's fracture energy."""
    from mpm_warp.field.static_view import static_view
    from mpm_warp.scenes.pst.static import static_column
    from mpm_warp.scenes.weac_reference import energy_release_rate

    a = static_view(cases[0].params).critical_cut
    assert 0.0 < a < 0.4
    assert energy_release_rate(static_column(cases[0].params), a)[0] == pytest.approx(0.3, rel=0.02)   # w_f given


def test_a_protocol_with_the_closure_refuses_a_column_with_a_layer_thinner_than_a_cell_in_field_terms(tmp_path):
    from mpm_warp.field.batch import _tasks

    (tmp_path / "slab.csv").write_text("thickness_cm,density\n0.5,250\n14.5,180\n")
    table = tmp_path / "psts.csv"
    table.write_text("id,outcome,slope_deg,column_cm,cut_cm,layers,weak_layer_cm,w_f\n"
                     "crust,End,0,40,12,slab.csv,4,0.3\n")
    cases, _ = gather([str(table)], calibrate=False)
    refused = []
    assert _tasks(cases, str(tmp_path), FieldProtocol(interface_closure=True), "cpu", refused) == []
    (r,) = refused
    assert r.reason == "thin layer" and r.message == (
        "the laminate closure needs every layer at least a grid cell thick, and slab layer 1 (from the top) is 5.0 "
        "mm, under the 10.00 mm cell the weak layer sets: run this column without --interface-closure")
    out = tmp_path / "run"                                  # the same through the CLI: refused, nothing run
    assert main(["field", str(table), "--out", str(out), "--interface-closure", "--quiet"]) == 0
    with open(out / "refused.csv") as fh:
        assert "psts.csv#crust,PST 12/40 (End) down 15 cm,End,thin layer,\"the laminate closure needs" in fh.read()


def test_a_brittle_slab_over_a_thick_weak_layer_gets_the_grid_its_crack_band_needs(tmp_path):
    """A 6 cm layer under 40 cm of 350 kg/m^3: at 4 cells across the layer (13 mm) the slab's crack band, 1.5 cells,
    would be wider than the snow's snap-back length 2 E G_f / sigma_t^2 (18.3 mm); the grid is refined to it."""
    from mpm_warp.field.batch import case_scenario

    table = tmp_path / "brittle.csv"
    table.write_text("id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,"
                     "column_ends\nthick,End,30,100,30,40,350,6,,0.5,\n")
    (case,), refused = gather([str(table)])
    assert refused == []
    p = case.params
    limit = min(ly.cracking(p.crack_band).max_band_width for ly in p.slab_stack())
    assert limit == pytest.approx(0.0183, abs=5e-5)
    assert p.dx < p.weak_layer_thickness / 4 and p.crack_band == pytest.approx(0.99 * limit)
    scenario, note = case_scenario(case, FieldProtocol())
    assert scenario is not None and note.startswith("4.3 cells across the weak layer, as the slab's crack band needs")


def test_a_run_of_another_selection_is_found_once_under_its_own_position(tmp_path, monkeypatch):
    """A case numbered k=3 in a batch of one selection is the same case at k=1 in another (same pit, same key):
    it is taken from there, each file once, so two identical records of a pit stay two cases; another pit's file
    with the same key, or the same pit's with another key, is not taken."""
    from mpm_warp.field import batch

    def finished(out):
        return {"id": os.path.basename(out), "status": "ok"} if os.path.exists(out + ".json") else None

    monkeypatch.setattr(batch.io, "finished_record", finished)
    for name in ("pit-a-3-0123456789ab", "pit-a-5-0123456789ab", "pit-a-9-fedcba987654", "pit-a-b-7-0123456789ab"):
        (tmp_path / f"{name}.json").write_text("{}")
    task = {"out_dir": str(tmp_path), "id": "pit-a-1-0123456789ab"}
    claimed = set()
    assert batch._finished(task, claimed)["id"] == "pit-a-3-0123456789ab"
    assert batch._finished({**task, "id": "pit-a-2-0123456789ab"}, claimed)["id"] == "pit-a-5-0123456789ab"
    assert batch._finished({**task, "id": "pit-a-4-0123456789ab"}, claimed) is None      # both taken
    assert batch._finished({**task, "id": "pit-a-5-0123456789ab"}, set())["id"] == "pit-a-5-0123456789ab"
    assert batch._finished({**task, "id": "pit-c-1-0123456789ab"}, set()) is None       # another pit
