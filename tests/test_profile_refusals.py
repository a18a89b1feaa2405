"""A bad snow profile is refused in one line that names the file, the layer and the value; no file hangs the reader."""

from __future__ import annotations

import os
import sys
import threading

import numpy as np
import pytest
from helpers_profile import write  # noqa: E402

from mpm_warp.scenes.profile import ProfileError, ProfileLibraryMissing, example_path, read_profile
from mpm_warp.scenes.profile.source import MAX_BYTES

OK = [(0.0, 0.3, "RG", None, "1F"), (0.3, 0.02, "SH", None, "F"), (0.32, 0.4, "RG", "FC", "P")]


def refused(path) -> str:
    """The one-line message of reading ``path``."""
    with pytest.raises(ProfileError) as e:
        read_profile(path)
    msg = str(e.value)
    assert "\n" not in msg and str(path) in msg
    return msg


@pytest.mark.parametrize("layers, text", [
    ([(0.0, 0.3, "RG", None, "1F"), (0.3, 0.0, "SH", None, "F"), (0.3, 0.3, "RG", None, "P")],
     "layer 1 (depth 0.3-0.3 m) thickness = 0.0 is invalid: expected a layer thickness > 0 m"),
    ([(0.0, 0.3, "RG", None, "1F"), (0.3, -0.05, "SH", None, "F"), (0.3, 0.3, "RG", None, "P")],
     "layer 1 (depth 0.3-0.25 m) thickness = -0.05 is invalid: expected a layer thickness > 0 m"),
    ([(0.0, 0.3, "RG", None, "1F"), (0.32, 0.3, "RG", None, "P")],
     "layer 1 (depth 0.32-0.62 m) depth_top = 0.32 is invalid: expected 0.3 m, the bottom of layer 0 (a gap of "
     "0.02 m: layers must be contiguous; a gap is not filled, its snow was not described)"),
    ([(0.0, 0.3, "RG", None, "1F"), (0.25, 0.3, "RG", None, "P")],
     "layer 1 (depth 0.25-0.55 m) depth_top = 0.25 is invalid: expected 0.3 m, the bottom of layer 0 (an overlap "
     "of 0.05 m"),
    ([(0.05, 0.3, "RG", None, "1F"), (0.35, 0.3, "RG", None, "P")],
     "layer 0 (depth 0.05-0.35 m) depth_top = 0.05 is invalid: expected 0 m: the first layer starts at the snow "
     "surface"),
    ([(0.0, 0.6, "RG", None, "1F"), (0.6, 0.6, "RG", None, "P")],
     "layer 1 (depth 0.6-1.2 m) depth_bottom = 1.2 is invalid: expected at most the snow depth HS = 1 m"),
])
def test_a_bad_layer_is_refused_naming_it(tmp_path, layers, text):
    assert text in refused(write(tmp_path, "bad.caaml", layers))


def test_a_contiguous_profile_within_rounding_is_read(tmp_path):
    # 0.3 mm between layers is rounding (tolerance 0.5 mm), not a gap
    p = read_profile(write(tmp_path, "ok.caaml", [(0.0, 0.3, "RG", None, "1F"), (0.3003, 0.3, "RG", None, "P")]))
    assert [L.depth_top for L in p.layers] == [0.0, 0.3003]


def test_a_bad_density_sample_is_refused_naming_it(tmp_path):
    msg = refused(write(tmp_path, "bad.caaml", OK, samples=[(0.1, 0.03, 200.0), (0.4, 0.0, 300.0)]))
    assert "density-profile sample 1 (depth 0.4 m) thickness = 0.0 is invalid: expected a sample thickness > 0 m" in msg


def _edit(tmp_path, old: str, new: str) -> str:
    text = open(example_path(), encoding="utf-8").read()
    assert old in text
    p = tmp_path / "edited.caaml"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return str(p)


@pytest.mark.parametrize("old, new, text", [
    ("<caaml:hardness uom=\"\">1F</caaml:hardness>", "<caaml:hardness uom=\"\">2F</caaml:hardness>",
     "layer 1 in the file (depth 0.1 m) hardness = '2F' is invalid: expected a hand hardness"),
    ("<caaml:grainFormPrimary>RG</caaml:grainFormPrimary>", "<caaml:grainFormPrimary>XX</caaml:grainFormPrimary>",
     "layer 3 in the file (depth 0.5 m) grainFormPrimary = 'XX' is invalid: expected an IACS grain shape code"),
    ("<caaml:thickness uom=\"cm\">38</caaml:thickness>", "<caaml:thickness uom=\"cm\">thirty</caaml:thickness>",
     "layer 1 in the file (depth 0.1 m) thickness = 'thirty' is invalid: expected a thickness in cm"),
    ("<caaml:density uom=\"kgm-3\">245</caaml:density>", "<caaml:density uom=\"kgm-3\">2450</caaml:density>",
     "density-profile sample 1 in the file (depth 0.35 m) density = '2450' is invalid: expected a density in (0, 917]"),
    ("<caaml:position>35</caaml:position>", "<caaml:position>95</caaml:position>",
     "a CAAML 6 profile that snowprofile reads (snowprofile says: slope: Input should be less than 90)"),
])
def test_a_value_the_library_refuses_is_named_with_its_layer(tmp_path, old, new, text):
    assert text in refused(_edit(tmp_path, old, new))


def test_missing_unreadable_and_odd_paths_are_refused(tmp_path):
    assert "expected an existing CAAML file (there is no such file)" in refused(tmp_path / "nope.caaml")
    assert "expected a regular CAAML file (this is a directory)" in refused(tmp_path)
    (tmp_path / "plain").write_text("x")
    assert "expected a readable CAAML file (Not a directory)" in refused(tmp_path / "plain" / "p.caaml")
    with pytest.raises(ProfileError, match="expected a path to a CAAML file"):
        read_profile(42)


def test_a_fifo_is_refused_without_hanging(tmp_path):
    fifo = tmp_path / "profile.caaml"
    os.mkfifo(fifo)
    out = {}

    def read():
        try:
            read_profile(fifo)
        except ProfileError as e:
            out["error"] = str(e)

    t = threading.Thread(target=read, daemon=True)     # a daemon: were it to block, the test run still ends
    t.start()
    t.join(timeout=20)
    assert not t.is_alive(), "reading a FIFO blocked"
    assert "expected a regular CAAML file (this is a FIFO (named pipe))" in out["error"]


def test_a_huge_file_is_refused_before_it_is_read(tmp_path):
    p = tmp_path / "huge.caaml"
    with open(p, "wb") as fh:
        fh.truncate(MAX_BYTES + 1)      # sparse: costs no disk
    assert "expected a CAAML file of at most 8 MiB (this one has 8 MiB)" in refused(p)


@pytest.mark.parametrize("content, text", [
    (b"", "the file is empty"),
    (b"   \n", "the file is empty"),
    (b"PST 32/100 (End), not XML", "it is not well-formed XML: syntax error: line 1, column 0"),
    (b'{"snowProfile": {}}', "this looks like JSON: export the profile as CAAML XML"),
    (b"<html><body>a web page</body></html>", "a CAAML SnowProfile document (its root element is 'html')"),
    (b'<SnowProfile xmlns="http://example.org/other"/>', "its namespace 'http://example.org/other' is not CAAML's"),
    (b'<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;">]>'
     b'<SnowProfile>&lol2;</SnowProfile>', "without a document type or entity declarations"),
    (b"\xff\xfe\x00<\x00b\x00a\x00d", "it is not well-formed XML"),
    (b'<?xml version="1.0" encoding="utf-9"?><SnowProfile/>', "it is not readable XML: unknown encoding: utf-9"),
    (b'<caaml:SnowProfile xmlns:caaml="http://caaml.org/Schemas/SnowProfileIACS/v6.0.3"/>',
     "a CAAML 6 profile that snowprofile reads"),
    (b"<SnowProfile>" + b"<a>" * 64 + b"</a>" * 64 + b"</SnowProfile>", "this one has nesting deeper than 64"),
    (b"<SnowProfile>" + b"<a/>" * 250_000 + b"</SnowProfile>", "this one has over 250000 elements"),
])
def test_a_file_that_is_not_a_caaml_profile_is_refused(tmp_path, content, text):
    p = tmp_path / "odd.caaml"
    p.write_bytes(content)
    assert text in refused(p)


def test_a_damaged_example_is_read_or_refused_in_one_line_never_crashes(tmp_path):
    """Truncations, deleted bytes and bytes replaced by digits or markup across the file: each one reads (a
    changed digit may still be a valid profile) or is refused as one ProfileError line, never another exception."""
    data = open(example_path(), "rb").read()
    rng = np.random.default_rng(21)
    damaged = [data[:n] for n in np.linspace(0, len(data), 13, dtype=int)[1:-1]]
    chars = b"0123456789-.<>/ aZ\xff"
    for k, off in enumerate(rng.choice(len(data), 150, replace=False)):
        b = bytearray(data)
        if k % 3 == 0:
            del b[off]
        else:
            b[off] = chars[int(rng.integers(len(chars)))]
        damaged.append(bytes(b))
    refusals = 0
    for i, d in enumerate(damaged):
        p = tmp_path / f"damaged{i}.caaml"
        p.write_bytes(d)
        try:
            read_profile(p)
        except ProfileError as e:
            refusals += 1
            assert "\n" not in str(e) and str(p) in str(e)
    assert refusals >= 11 + 50      # every truncation, and most damaged bytes


def test_without_snowprofile_one_line_says_how_to_install_it(monkeypatch):
    for name in [m for m in sys.modules if m == "snowprofile" or m.startswith("snowprofile.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "snowprofile", None)      # import snowprofile raises ImportError
    with pytest.raises(ProfileLibraryMissing) as e:
        read_profile(example_path())
    assert "pip install 'mpm-warp[profile]'" in str(e.value) and "\n" not in str(e.value)
