"""Reading a CAAML snow profile (as SnowPilot, niViz and other field apps export it) into plain records.

A SnowPilot export (CAAML 6.0.3) is parsed by ``snowpylot`` (:mod:`.snowpilot`), any other CAAML 6 XML
(6.0.3 to 6.0.5) or CAAML 5 XML by ``snowprofile`` (UMR-CNRM); both are in the optional extra ``profile``
(``pip install 'mpm-warp[profile]'``). Then the layers are checked and get their densities
(:mod:`.stratigraphy`). What is refused, and why gaps are not filled, is in docs/profiles.md; every refusal
is one :class:`ProfileError` line naming the file, the layer (index from the top and depth) and the value.
"""

from __future__ import annotations

import io
import logging
import math
from contextlib import contextmanager

import numpy as np

from .diagnose import diagnose_layers
from .records import ProfileError, ProfileLayer, ProfileLibraryMissing, PSTRecord, SnowProfileData
from .snowpilot import is_snowpilot, read_snowpilot
from .source import caaml_version, read_capped
from .stratigraphy import TOLERANCE, build_layers, check_samples

__all__ = ["read_profile", "TOLERANCE", "import_snowprofile"]

INSTALL = "pip install 'mpm-warp[profile]' (or: pip install snowprofile 'pandas<3')"


def import_snowprofile():
    """The ``snowprofile.io`` module; :class:`ProfileLibraryMissing` (one line: how to install it) without it."""
    try:
        import snowprofile.io as sp_io
    except ImportError as e:
        raise ProfileLibraryMissing(f"reading a CAAML snow profile needs the snowprofile library ({e}): "
                                    f"{INSTALL}", e) from None
    return sp_io


class _Collect(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(record.getMessage())


@contextmanager
def _collect_root_log():
    """snowprofile logs its reasons on the root logger: keep them for our message (and leave logging unconfigured)."""
    root, handler = logging.getLogger(), _Collect()
    root.addHandler(handler)
    try:
        yield handler.messages
    finally:
        root.removeHandler(handler)


def _one_line(e: BaseException) -> str:
    errors = getattr(e, "errors", None)
    if callable(errors):        # pydantic: "location.slope: Input should be less than 90"
        try:
            first = errors()[0]
            return f"{'.'.join(str(p) for p in first.get('loc', ()))}: {first.get('msg', '')}".strip(": ")
        except Exception:       # any shape of pydantic's error list: fall back to the text
            pass
    text = " ".join(str(e).split())
    return (text[:300] + "...") if len(text) > 300 else (text or type(e).__name__)


def _pandas_hint() -> str:
    try:
        import pandas
        if int(pandas.__version__.split(".")[0]) >= 3:
            return (f" (pandas {pandas.__version__} turns a missing value into NaN, which snowprofile refuses: "
                    "pip install 'pandas<3')")
    except Exception:           # a hint only
        pass
    return ""


def _parse(data: bytes, version: str, path: str):
    sp_io = import_snowprofile()
    reader = sp_io.read_caaml5_xml if version == "5" else sp_io.read_caaml6_xml
    with _collect_root_log() as log:
        try:
            sp = reader(io.BytesIO(data))
        except Exception as e:  # any failure of the library is a refusal of the file
            diagnose_layers(data, path)         # a layer it can name first
            raise ProfileError("profile", path, f"a CAAML {version} profile that snowprofile reads (snowprofile says: "
                                                f"{_one_line(e)}){_pandas_hint()}") from None
    if sp is None:
        reason = log[0] if log else "no reason given"
        raise ProfileError("profile", path, f"a CAAML {version} profile that snowprofile reads "
                                            f"(snowprofile says: {reason})")
    return sp


def _text(v) -> str | None:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return None
    return str(v)


def _column(df, name: str) -> list:
    return list(df[name]) if name in df.columns else [None] * len(df)


def _depth_origin(profile, sp) -> float:
    """The snow depth the library subtracted CAAML depths from (m): the profile's own, HS, or 0."""
    for h in (getattr(profile, "profile_depth", None), sp.profile_depth):
        if h is not None:
            return float(h)
    return 0.0


def _samples(sp, path: str) -> np.ndarray:
    """The first density profile's samples as rows (top, bottom, density), depths in m; checked."""
    if not sp.density_profiles:
        return np.zeros((0, 3))
    prof = sp.density_profiles[0]
    df, h0 = prof.data, _depth_origin(prof, sp)
    columns = (_column(df, "top_height"), _column(df, "thickness"), _column(df, "density"))
    return check_samples([(h0 - float(top), th, rho) for top, th, rho in zip(*columns, strict=True)], path)


def _layers(sp, path: str) -> tuple[ProfileLayer, ...]:
    strat = sp.stratigraphy_profile
    if strat is None or strat.data is None or len(strat.data) == 0:
        raise ProfileError("profile", path, "a CAAML profile with a stratigraphy (it has no stratigraphy layers)")
    df, h0 = strat.data, _depth_origin(strat, sp)
    tops = h0 - np.array(_column(df, "top_height"), dtype=float)
    ths = [np.nan if t is None else float(t) for t in _column(df, "thickness")]
    hard, g1s, g2s = (list(map(_text, _column(df, k))) for k in ("hardness", "grain_1", "grain_2"))
    return build_layers(tops, ths, hard, g1s, g2s, _samples(sp, path), sp.profile_depth, path)


def _psts(sp) -> tuple[PSTRecord, ...]:
    out = []
    for t in sp.stability_tests:
        if getattr(t, "type", None) != "PST":
            continue
        depth = None
        if t.height is not None and sp.profile_depth is not None:
            depth = round(float(sp.profile_depth) - float(t.height), 6)
        out.append(PSTRecord(cut_length=None if t.cut_length is None else float(t.cut_length),
                             column_length=None if t.column_length is None else float(t.column_length),
                             propagation=t.propagation, depth=depth,
                             layer_thickness=None if t.layer_thickness is None else float(t.layer_thickness),
                             grain_1=t.grain_1))
    return tuple(out)


def read_profile(path) -> SnowProfileData:
    """Read a CAAML 5 or 6 XML snow profile.

    Parameters
    ----------
    path : str or os.PathLike
        A regular file of at most :data:`~mpm_warp.scenes.profile.source.MAX_BYTES` bytes.

    Returns
    -------
    SnowProfileData
        The layers top to bottom (depths and thicknesses in m, densities in kg/m^3 with their source),
        the site (slope angle and aspect in deg, location name, date), HS (m) and the PST results.

    Notes
    -----
    A SnowPilot export (CAAML 6.0.3) is read by snowpylot (:mod:`.snowpilot`), every other CAAML 5 or 6
    file by snowprofile. A layer without a density (no hardness, no grain, a grain without a law) is kept
    with the reason as its density source: it refuses a PST only where the model needs it (:mod:`.column`).

    Raises
    ------
    ProfileError
        One line naming the file and, for a bad layer, the layer (index from the top, depth) and the value:
        no such file, not a regular file, too large, not XML, not CAAML, a layer of zero or negative
        thickness, a gap or overlap between layers.
    ProfileLibraryMissing
        The library that reads this file is not installed (the line says how to install it).
    """
    data = read_capped(path)
    path = str(path)
    version = caaml_version(data, path)
    if version == "6" and is_snowpilot(data):
        return read_snowpilot(data, path)
    sp = _parse(data, version, path)
    layers = _layers(sp, path)
    loc = sp.location
    hs = sp.profile_depth if sp.profile_depth is not None and sp.profile_depth > 0 else layers[-1].depth_bottom
    return SnowProfileData(
        layers=layers,
        slope_angle=None if loc.slope is None else float(loc.slope),
        aspect=None if loc.aspect is None else float(loc.aspect),
        location=loc.name,
        date=sp.time.record_time,
        total_depth=float(hs),
        pst_tests=_psts(sp),
        source=path,
        caaml_version=version)
