"""A study's kept per-case records (``mpm_warp.field.run_on.kept_record``): reused only by the same study."""

from __future__ import annotations

import json

import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.field.run_on import kept_record

STUDY = {"runs": "field_runs_v5", "after_s": 0.1}


def _write(path, rec):
    path.write_text(json.dumps(rec))
    return str(path)


def test_no_record_is_none(tmp_path):
    assert kept_record(str(tmp_path / "case.landing.json"), STUDY) is None


def test_the_same_study_reuses_its_record(tmp_path):
    rec = {**STUDY, "id": "case", "status": "ok", "body_peak_after": 0.4}
    assert kept_record(_write(tmp_path / "case.landing.json", rec), STUDY) == rec


@pytest.mark.parametrize("other", [{"runs": "field_runs_v4", "after_s": 0.1}, {"runs": "field_runs_v5", "after_s": 0.2},
                                   {"id": "case"}])
def test_another_study_s_record_is_refused_and_kept(tmp_path, other):
    """A record of another runs folder or time, or from before records named their study, is refused in one line
    naming the folder and the file, and left as it was."""
    path = _write(tmp_path / "case.landing.json", {**other, "status": "ok"})
    before = open(path).read()
    with pytest.raises(InvalidArgument, match=r"work = .*case\.landing\.json was made with"):
        kept_record(path, STUDY)
    assert open(path).read() == before
