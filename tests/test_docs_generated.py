"""The command-line and scenario key references in docs/scenarios.md and the README's command table are
generated from the code (``python -m mpm_warp.docgen``): the committed files are current, and
the generators read what the code says (every flag, every field, the ranges the checks enforce)."""

from __future__ import annotations

import dataclasses
import difflib
import os

import pytest

from mpm_warp.cli import build_parser
from mpm_warp.docgen import generated_files, main
from mpm_warp.docgen.cli_doc import cli_lines, readme_lines, subcommands
from mpm_warp.docgen.dataclass_doc import check_ranges, field_docs
from mpm_warp.docgen.keys_doc import keys_lines
from mpm_warp.scenes.pst import PSTParams
from mpm_warp.scenes.pst.params import Saw

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.mark.parametrize("rel", ["docs/scenarios.md", "README.md"])
def test_committed_generated_blocks_are_current(rel):
    old, new = generated_files(ROOT)[rel]
    diff = "\n".join(list(difflib.unified_diff(old.splitlines(), new.splitlines(), lineterm="", n=1))[:30])
    assert old == new, f"{rel} is out of date: run `python -m mpm_warp.docgen` and commit\n{diff}"


def test_check_mode_reports_a_stale_file(tmp_path):
    for rel in ("docs/scenarios.md", "README.md"):
        os.makedirs(tmp_path / os.path.dirname(rel), exist_ok=True)
        text = open(os.path.join(ROOT, rel)).read()
        (tmp_path / rel).write_text(text.replace("| `--overwrite` |", "| `--overwritten` |"))
    assert main(["--root", str(tmp_path), "--check"]) == 1
    assert main(["--root", str(tmp_path)]) == 0
    assert main(["--root", str(tmp_path), "--check"]) == 0
    assert (tmp_path / "docs/scenarios.md").read_text() == open(os.path.join(ROOT, "docs/scenarios.md")).read()


def test_every_subcommand_and_flag_is_in_the_cli_reference():
    parser = build_parser()
    text = "\n".join(cli_lines(parser))
    table = "\n".join(readme_lines(parser))
    names = [name for name, _, _ in subcommands(parser)]
    assert {"run", "resume", "render", "plot", "profile", "sweep", "scenes", "info"} <= set(names)
    for name, _, p in subcommands(parser):
        assert f"### `mpm-warp {name}`" in text and f"`mpm-warp {name}" in table
        for a in p._actions:
            for flag in a.option_strings:
                if flag not in ("-h", "--help"):
                    assert f"`{flag}" in text, (name, flag)
    assert "[--out OUT]" in text           # --out is optional for run (default: no output)


def test_field_docs_read_type_default_and_unit():
    by_name = {f.name: f for f in field_docs(PSTParams)}
    assert [f.name for f in dataclasses.fields(PSTParams)] == list(by_name)
    assert (by_name["slope_angle"].type, by_name["slope_angle"].default, by_name["slope_angle"].unit) == \
        ("number", "0", "deg")
    assert by_name["dx"].default == "0.0075" and by_name["dx"].unit == "m"
    assert by_name["column_ends"].type == '"slope_normal" \\| "vertical"'
    assert by_name["saw"].nested is Saw and by_name["slab_layers"].type == "list of tables"


def test_ranges_come_from_the_checks():
    r = check_ranges(PSTParams.validate)
    assert r["saw.speed"] == ["in (0, 1]"]
    assert r["saw.cut_length"] == ["in [0, length]"]
    assert r["margin"] == [">= 2 dx"]
    assert r["particles_per_cell"] == ["integer in [1, 8]"]
    assert r["slope_angle"] == ["in [-60, 60]"]


def test_an_undocumented_field_is_refused():
    @dataclasses.dataclass
    class P:
        """Parameters.

        Attributes
        ----------
        a : float
            Length (m), > 0.
        """

        a: float = 1.0
        b: float = 2.0

    with pytest.raises(ValueError, match="'b' is not in its docstring"):
        field_docs(P)


def test_key_reference_has_every_scene_table():
    text = "\n".join(keys_lines())
    for heading in ("`[domain]`", "`[time]`", "`[output]`", "`[[blocks]]`", "`[[walls]]`", '`model = "camclay"`',
                    '`model = "bonded_camclay"`', '`model = "tensile_cracking"`', '`[scene] kind = "pst"`',
                    "`[scene.saw]`", "`[scene.weak_layer]`", "`[scene.profile]`", "`[[scene.slab_layers]]`",
                    '`[scene] kind = "shear_test"`'):
        assert heading in text, heading
    assert "`kappa` (" in text and "`damage` (" in text
