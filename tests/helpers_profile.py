"""Small CAAML profiles for the profile tests, written with snowprofile's own writer (or by hand for CAAML 5)."""

from __future__ import annotations

import datetime
import io


def caaml_bytes(layers, samples=(), hs=1.0, psts=(), slope=30):
    """CAAML 6 bytes of a profile: ``layers`` rows (depth top m, thickness m, grain 1, grain 2, hardness),
    ``samples`` rows (depth top m, thickness m, density kg/m^3), ``psts`` rows (cut m, column m, End/SF/Arr, depth m).
    """
    from snowprofile import SnowProfile
    from snowprofile.classes import Location, Observer, Person, Time
    from snowprofile.io import write_caaml6_xml
    from snowprofile.profiles import DensityProfile, Stratigraphy
    from snowprofile.stability_tests import PSTStabilityTest

    strat = Stratigraphy(data=dict(
        top_height=[hs - r[0] for r in layers], thickness=[r[1] for r in layers], grain_1=[r[2] for r in layers],
        grain_2=[r[3] for r in layers], hardness=[r[4] for r in layers], grain_size=[1e-3] * len(layers),
        wetness=["D"] * len(layers)))
    dens = [DensityProfile(data=dict(top_height=[hs - s[0] for s in samples], thickness=[s[1] for s in samples],
                                     density=[s[2] for s in samples]))] if samples else []
    tests = [PSTStabilityTest(cut_length=c, column_length=L, propagation=p, height=hs - d) for c, L, p, d in psts]
    sp = SnowProfile(time=Time(record_time=datetime.datetime(2025, 1, 2, 12, 0, tzinfo=datetime.timezone.utc)),
                     observer=Observer(source_name="test", contact_persons=[Person(name="test")]),
                     location=Location(name="test site", slope=slope, aspect=90), profile_depth=hs,
                     stratigraphy_profile=strat, density_profiles=dens, stability_tests=tests)
    buf = io.BytesIO()
    write_caaml6_xml(sp, buf, indent=True)
    return buf.getvalue()


def write(tmp_path, name, layers, **kw):
    """Write :func:`caaml_bytes` to ``tmp_path / name``; return the path as str."""
    p = tmp_path / name
    p.write_bytes(caaml_bytes(layers, **kw))
    return str(p)
