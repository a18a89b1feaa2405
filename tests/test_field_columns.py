"""``mpm-warp field --columns N``: the batch's cases stepped together in groups, each with its own record."""

from __future__ import annotations

import json
import os

import pytest

from mpm_warp.cli import main
from mpm_warp.field.batch import column_groups
from mpm_warp.field.protocol import FieldProtocol

TABLE = """id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends
tiny-a,End,0,40,12,15,180,4,,0.3,
tiny-b,Arr,0,40,15,15,180,4,,0.5,vertical
tiny-c,End,0,40,12,15,180,5,,0.3,
"""


def _records(out: str) -> dict:
    recs = {}
    for name in sorted(os.listdir(out)):
        if name.endswith(".json") and name not in ("scores.json", "calibration.json"):
            with open(os.path.join(out, name)) as fh:
                r = json.load(fh)
            recs[r["pit"]] = r
    return recs


@pytest.mark.slow
def test_cases_stepped_together_keep_their_class_and_say_what_the_shared_step_cost(tmp_path, capsys):
    pytest.importorskip("distributed")
    pytest.importorskip("weac")
    table = tmp_path / "psts.csv"
    table.write_text(TABLE)
    alone, together = str(tmp_path / "alone"), str(tmp_path / "together")
    assert main(["field", str(table), "--out", alone, "--workers", "1", "--quiet"]) == 0
    assert main(["field", str(table), "--out", together, "--workers", "1", "--columns", "3", "--quiet"]) == 0
    a, t = _records(alone), _records(together)
    assert sorted(a) == sorted(t) == ["psts.csv#tiny-a", "psts.csv#tiny-b", "psts.csv#tiny-c"]
    for pit in a:
        assert t[pit]["status"] == a[pit]["status"] == "ok"
        assert t[pit]["predicted"] == a[pit]["predicted"]
        assert t[pit]["sim_time"] == pytest.approx(a[pit]["sim_time"], abs=1e-9)   # decided at the same frame
        assert t[pit]["columns"] == 3 and "columns" not in a[pit]
        assert t[pit]["id"] != a[pit]["id"]                  # a shared step is another computation: another key
    # the 5 cm weak layer's coarser grid steps longer alone: in the group it steps with the 4 cm columns' step
    costs = {pit: r["shared_step_cost"] for pit, r in t.items()}
    assert costs["psts.csv#tiny-a"] == costs["psts.csv#tiny-b"] == 1.0
    assert costs["psts.csv#tiny-c"] == pytest.approx(1.25, rel=1e-6)      # dx 12.5 mm against 10 mm, same snow
    assert t["psts.csv#tiny-c"]["steps"] > a["psts.csv#tiny-c"]["steps"]
    # a rerun finds every case of the group finished and runs none
    assert main(["field", str(table), "--out", together, "--workers", "1", "--columns", "3", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "(3 from an earlier batch)" in out and "ranked probability skill against the cases' climatology" in out
    # the lone batch's calibration (END and ARR) applied to the grouped one: how many columns step together aside,
    # the protocols are the same
    cal = os.path.join(alone, "calibration.json")
    assert main(["field", str(table), "--out", together, "--workers", "1", "--columns", "3", "--quiet",
                 "--calibration", cal]) == 0
    out = capsys.readouterr().out
    assert "calibration file " in out and "calibration file -" not in out


def test_groups_of_columns_come_sorted_by_their_own_step_within_a_window(monkeypatch):
    from mpm_warp.field import batch

    monkeypatch.setattr(batch, "column_step", lambda step: step)        # a task's "scenario" is its step here
    tasks = [{"id": str(k), "scenario": dt} for k, dt in enumerate([0.01, 0.004, 0.008, 0.002, 0.006])]
    groups = list(column_groups(iter(tasks), 2, window=2))
    # the first window (4 tasks) sorted by step, in groups of 2; the fifth alone
    assert [[t["id"] for t in g] for g in groups] == [["3", "1"], ["2", "0"], ["4"]]
    with pytest.raises(Exception, match="columns"):
        FieldProtocol(columns=0).validate()
    assert "columns" not in FieldProtocol().run_key() and FieldProtocol(columns=8).run_key()["columns"] == 8
