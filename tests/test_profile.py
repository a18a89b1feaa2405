"""A snow profile as input: the shipped CAAML example, densities from the profile, CAAML 5, the weak layer's choice."""

from __future__ import annotations

import datetime

import numpy as np
import pytest
from helpers_profile import write  # noqa: E402

from mpm_warp.errors import InvalidArgument, OutputError
from mpm_warp.scenes.profile import (
    ProfileError,
    example_bytes,
    example_path,
    read_profile,
    select_weak_layer,
    write_example,
)


def test_the_example_reads_back_with_its_densities_site_and_pst():
    p = read_profile(example_path())
    assert p.caaml_version == "6" and p.location == "Example slope (synthetic)"
    assert (p.slope_angle, p.aspect, p.total_depth) == (35.0, 20.0, 1.2)
    assert p.date == datetime.datetime(2024, 2, 14, 10, 30, tzinfo=datetime.timezone.utc)
    assert [(L.depth_top, L.thickness) for L in p.layers] == [
        (0.0, 0.1), (0.1, 0.38), (0.48, 0.02), (0.5, 0.3), (0.8, 0.25), (1.05, 0.15)]
    assert [(L.grain_1, L.grain_2, L.hardness) for L in p.layers] == [
        ("PP", None, "F"), ("RGwp", "DF", "1F"), ("SH", None, "F"), ("RG", "FC", "P"), ("FCxr", "RG", "1F+"),
        ("DH", "FC", "4F")]
    rho = [L.density for L in p.layers]
    # PP, F: 45 + 36; two 3 cm samples 215 and 245 in layer 1; SH: no law, weac's grain-type 125; one sample 300;
    # FCxr (class FCmx), 1F+: 56 + 64 (3 + 1/3); DH, 4F: 185 + 25 * 2
    assert rho[0] == pytest.approx(81.0, abs=1e-9) and rho[1] == pytest.approx(230.0, abs=1e-9)
    assert rho[2] == 125.0 and p.layers[2].density_source.startswith("fallback: grain-type value for SH")
    assert rho[3] == pytest.approx(300.0, abs=1e-9)
    assert rho[4] == pytest.approx(56 + 64 * 10 / 3, abs=1e-9) and rho[5] == pytest.approx(235.0, abs=1e-9)
    assert p.layers[0].density_source == "Geldsetzer and Jamieson 2000 from hardness F and grain PP"
    assert p.layers[4].density_source == "Geldsetzer and Jamieson 2000 from hardness 1F+ and grain FCxr (class FCmx)"
    assert [L.measured for L in p.layers] == [False, True, False, True, False, False]
    (pst,) = p.pst_tests
    assert (pst.cut_length, pst.column_length, pst.propagation, pst.depth) == (0.32, 1.0, "End", 0.48)
    assert pst.grain_1 == "SH" and pst.field_line() == "PST 32/100 (End) down 48 cm"
    assert "PST 32/100 (End)" in p.summary() and len(p.summary().splitlines()) == 1 + 6 + 1


def test_the_shipped_example_is_what_the_writer_writes(tmp_path):
    with open(example_path(), "rb") as fh:
        shipped = fh.read()
    assert example_bytes() == shipped          # snowprofile's writer puts no timestamp in it
    out = tmp_path / "mine.caaml"
    assert write_example(out) == str(out) and out.read_bytes() == shipped
    out.write_text("the user's own file")
    with pytest.raises(OutputError, match="exists; pass overwrite=True"):
        write_example(out)
    assert out.read_text() == "the user's own file"
    write_example(out, overwrite=True)
    assert out.read_bytes() == shipped and read_profile(out).layers[2].grain_1 == "SH"


def test_the_weak_layer_by_its_depth_or_index(tmp_path):
    p = read_profile(example_path())
    slab, weak, below = select_weak_layer(p, depth=p.pst_tests[0].depth)
    assert weak.index == 2 and [L.index for L in slab] == [0, 1] and [L.index for L in below] == [3, 4, 5]
    assert select_weak_layer(p, depth=0.499)[1].index == 2       # inside the layer
    assert select_weak_layer(p, index=2) == (slab, weak, below) == select_weak_layer(p, index=np.int64(2))
    assert select_weak_layer(p, depth=np.float32(0.49))[1].index == 2
    assert sum(L.density * L.thickness for L in slab) == pytest.approx(81 * 0.1 + 230 * 0.38)   # kg/m^2
    q = read_profile(write(tmp_path, "q.caaml", [(0.0, 0.1, "PP", None, "F"), (0.1, 0.2, "RG", None, "1F"),
                                                 (0.3, 0.05, "FC", None, "4F")]))
    assert select_weak_layer(q, depth=0.1)[1].index == 1          # a boundary names the layer below it
    assert select_weak_layer(q, depth=0.3 - 1e-9)[1].index == 1
    slab, weak, below = select_weak_layer(q, index=2)
    assert [L.index for L in slab] == [0, 1] and weak.index == 2 and below == ()   # the pit ends at the weak layer


@pytest.mark.parametrize("kw, text", [
    (dict(depth=1.2), "weak layer depth = 1.2 is invalid: expected a depth in [0.1, 1.2) m"),
    (dict(depth=0.05), "weak layer depth = 0.05 is invalid: expected a depth in [0.1, 1.2) m"),
    (dict(depth=-0.1), "weak layer depth = -0.1 is invalid"),
    (dict(depth=float("nan")), "weak layer depth = nan is invalid"),
    (dict(index=0), "weak layer index = 0 is invalid: expected an integer in [1, 5]"),
    (dict(index=6), "weak layer index = 6 is invalid: expected an integer in [1, 5]"),
    (dict(index=-1), "weak layer index = -1 is invalid"),
    (dict(index=2.0), "weak layer index = 2.0 is invalid"),
    (dict(), "weak layer = {'depth': None, 'index': None} is invalid: expected exactly one of depth"),
    (dict(depth=0.48, index=2), "expected exactly one of depth (m) and index"),
])
def test_a_weak_layer_out_of_range_is_refused_in_one_line(kw, text):
    p = read_profile(example_path())
    with pytest.raises(ProfileError) as e:
        select_weak_layer(p, **kw)
    assert text in str(e.value) and "\n" not in str(e.value) and isinstance(e.value, InvalidArgument)


def test_a_slab_layer_without_density_is_refused_naming_it(tmp_path):
    path = write(tmp_path, "bare.caaml", [(0.0, 0.3, "RG", None, "1F"), (0.3, 0.2, None, None, None),
                                          (0.5, 0.3, "FC", None, "F")])
    with pytest.raises(ProfileError) as e:
        select_weak_layer(read_profile(path), index=2)           # the bare layer would be in the slab
    msg = str(e.value)
    assert "layer 1 (depth 0.3-0.5 m) density = None is invalid: expected a density for a slab layer" in msg
    assert "neither a hand hardness nor a grain form recorded" in msg and "\n" not in msg


def test_a_layer_takes_the_overlap_weighted_density_of_the_samples(tmp_path):
    # samples 0.25-0.35 m (200) and 0.40-0.43 m (300): layer 0 sees 5 cm of the first; layer 1 the other 5 cm
    # and all of the second: (0.05 * 200 + 0.03 * 300) / 0.08 = 237.5; layer 2 none: from its hardness and grain
    path = write(tmp_path, "overlap.caaml", [(0.0, 0.3, "RG", None, "1F"), (0.3, 0.3, "RG", None, "P"),
                                             (0.6, 0.4, "FC", None, "4F")],
                 samples=[(0.25, 0.10, 200.0), (0.40, 0.03, 300.0)])
    L = read_profile(path).layers
    assert L[0].density == pytest.approx(200.0) and L[1].density == pytest.approx(237.5)
    assert L[0].measured and L[1].measured and L[2].density == pytest.approx(112 + 46 * 2)


def test_a_sample_touching_a_layer_by_rounding_only_does_not_count(tmp_path):
    # 0.4 mm of a sample in layer 0 (below the 0.5 mm tolerance): layer 0 keeps its hardness law
    path = write(tmp_path, "touch.caaml", [(0.0, 0.3, "DF", None, "4F"), (0.3, 0.3, "RG", None, "P")],
                 samples=[(0.2996, 0.03, 250.0)])
    L = read_profile(path).layers
    assert L[0].density == pytest.approx(65 + 36 * 2) and not L[0].measured and L[1].density == pytest.approx(250.0)


def test_the_secondary_grain_and_extrapolation_are_named_in_the_source(tmp_path):
    path = write(tmp_path, "sh.caaml", [(0.0, 0.3, "PP", None, "K"), (0.3, 0.01, "SH", "FC", "F"),
                                        (0.31, 0.3, "MFcr", None, "K")])
    L = read_profile(path).layers
    assert L[0].density == pytest.approx(45 + 36 * 5)
    assert L[0].density_source.endswith("extrapolated beyond the fit's hardness F- to P")
    assert L[1].density == pytest.approx(112 + 46 * 1)
    assert L[1].density_source == ("Geldsetzer and Jamieson 2000 from hardness F and grain FC, the secondary grain: "
                                   "SH has no law")
    # a melt-freeze crust has no hardness law: weac's grain-type value, flagged as a fallback
    assert L[2].density == 292.25
    assert L[2].density_source == "fallback: grain-type value for MFcr (weac's table: no hardness law for this grain)"


#: a minimal CAAML 5 profile written by hand (CAAMLv5_SnowProfileIACS.xsd: depths top down, in cm)
CAAML5 = """<?xml version="1.0" encoding="UTF-8"?>
<caaml:SnowProfile xmlns:caaml="http://caaml.org/Schemas/V5.0/Profiles/SnowProfileIACS"
    xmlns:gml="http://www.opengis.net/gml" gml:id="p5">
  <caaml:validTime><caaml:TimeInstant><caaml:timePosition>2012-03-01T09:15:00+01:00</caaml:timePosition>
  </caaml:TimeInstant></caaml:validTime>
  <caaml:snowProfileResultsOf><caaml:SnowProfileMeasurements dir="top down">
    <caaml:profileDepth uom="cm">90</caaml:profileDepth>
    <caaml:snowPackCond><caaml:hS><caaml:Components><caaml:snowHeight uom="cm">90</caaml:snowHeight>
    </caaml:Components></caaml:hS></caaml:snowPackCond>
    <caaml:stratProfile>
      <caaml:Layer><caaml:depthTop uom="cm">0</caaml:depthTop><caaml:thickness uom="cm">35</caaml:thickness>
        <caaml:grainFormPrimary>RG</caaml:grainFormPrimary><caaml:grainFormSecondary>DF</caaml:grainFormSecondary>
        <caaml:hardness uom="">4F-1F</caaml:hardness></caaml:Layer>
      <caaml:Layer><caaml:depthTop uom="cm">35</caaml:depthTop><caaml:thickness uom="cm">3</caaml:thickness>
        <caaml:grainFormPrimary>FC</caaml:grainFormPrimary><caaml:grainFormSecondary>DH</caaml:grainFormSecondary>
        <caaml:hardness uom="">4F</caaml:hardness></caaml:Layer>
      <caaml:Layer><caaml:depthTop uom="cm">38</caaml:depthTop><caaml:thickness uom="cm">52</caaml:thickness>
        <caaml:grainFormPrimary>RG</caaml:grainFormPrimary><caaml:grainFormSecondary>RG</caaml:grainFormSecondary>
        <caaml:hardness uom="">P</caaml:hardness></caaml:Layer>
    </caaml:stratProfile>
    <caaml:densityProfile>
      <caaml:Layer><caaml:depthTop uom="cm">50</caaml:depthTop><caaml:thickness uom="cm">10</caaml:thickness>
        <caaml:density uom="kgm-3">320</caaml:density></caaml:Layer>
    </caaml:densityProfile>
    <caaml:stbTests><caaml:PropSawTest><caaml:failedOn>
      <caaml:Layer><caaml:depthTop uom="cm">35</caaml:depthTop><caaml:thickness uom="cm">3</caaml:thickness>
        <caaml:grainFormPrimary>FC</caaml:grainFormPrimary></caaml:Layer>
      <caaml:Results><caaml:fracturePropagation>Arr</caaml:fracturePropagation>
        <caaml:cutLength uom="cm">45</caaml:cutLength><caaml:columnLength uom="cm">120</caaml:columnLength>
      </caaml:Results>
    </caaml:failedOn></caaml:PropSawTest></caaml:stbTests>
  </caaml:SnowProfileMeasurements></caaml:snowProfileResultsOf>
  <caaml:locRef><caaml:ObsPoint gml:id="site"><caaml:name>CAAML 5 site</caaml:name>
    <caaml:validAspect><caaml:AspectPosition><caaml:position>NE</caaml:position></caaml:AspectPosition>
    </caaml:validAspect>
    <caaml:validSlopeAngle><caaml:SlopeAnglePosition><caaml:position>38</caaml:position></caaml:SlopeAnglePosition>
    </caaml:validSlopeAngle>
  </caaml:ObsPoint></caaml:locRef>
</caaml:SnowProfile>
"""


def test_a_caaml5_profile_is_read(tmp_path):
    path = tmp_path / "v5.caaml"
    path.write_text(CAAML5)
    p = read_profile(path)
    assert p.caaml_version == "5" and p.location == "CAAML 5 site"
    assert (p.slope_angle, p.aspect, p.total_depth) == (38.0, 45.0, 0.9)
    assert p.date == datetime.datetime(2012, 3, 1, 8, 15, tzinfo=datetime.timezone.utc)
    assert [(L.depth_top, L.thickness, L.hardness) for L in p.layers] == [
        (0.0, 0.35, "4F-1F"), (0.35, 0.03, "4F"), (0.38, 0.52, "P")]
    # RG at 4F-1F (index 2.5): 154 + 1.51 * 2.5^3.15; FC 4F: 112 + 46 * 2; the bottom layer's sample: 320
    assert p.layers[0].density == pytest.approx(154 + 1.51 * 2.5 ** 3.15)
    assert p.layers[1].density == pytest.approx(204.0) and p.layers[2].density == pytest.approx(320.0)
    (pst,) = p.pst_tests
    assert (pst.cut_length, pst.column_length, pst.propagation, pst.depth) == (0.45, 1.2, "Arr", 0.35)
    assert select_weak_layer(p, depth=pst.depth)[1].grain_1 == "FC"
