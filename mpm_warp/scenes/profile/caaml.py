"""Reading a CAAML snow profile (as SnowPilot, niViz and other field apps export it) into plain records.

The file is parsed by the ``snowprofile`` library (UMR-CNRM, the optional extra ``profile``:
``pip install 'mpm-warp[profile]'``): CAAML 6 XML (6.0.3 to 6.0.5) and CAAML 5 XML. Then every
layer is checked and gets its density: from the profile's density profile where a sample overlaps
it, otherwise from its hand hardness and grain form (:mod:`..density_laws`). What is refused, and why
gaps are not filled, is in docs/profiles.md; every refusal is one :class:`ProfileError` line naming
the file, the layer (index from the top and depth) and the value.
"""

from __future__ import annotations

import io
import logging
import math
from contextlib import contextmanager

import numpy as np

from ..density_laws import GJ_FITS, GRAIN_CLASS, HARDNESS_INDEX, geldsetzer_jamieson_density
from .diagnose import diagnose_layers
from .records import MEASURED, ProfileError, ProfileLayer, ProfileLibraryMissing, PSTRecord, SnowProfileData, metres
from .source import caaml_version, read_capped

__all__ = ["read_profile", "TOLERANCE", "import_snowprofile"]

#: largest mismatch between consecutive layers taken as rounding (m): field profiles are recorded to
#: 0.5-1 cm, so half a millimetre is never snow; a larger gap or overlap is refused
TOLERANCE = 5.0e-4

INSTALL = "pip install 'mpm-warp[profile]' (or: pip install snowprofile 'pandas<3')"


def import_snowprofile():
    """The ``snowprofile.io`` module; :class:`ProfileLibraryMissing` (one line: how to install it) without it."""
    try:
        import snowprofile.io as sp_io
    except ImportError as e:
        raise ProfileLibraryMissing(f"reading a CAAML snow profile needs the snowprofile library ({e}): "
                                    f"{INSTALL}") from None
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
    rows = []
    columns = (_column(df, "top_height"), _column(df, "thickness"), _column(df, "density"))
    for k, (top, th, rho) in enumerate(zip(*columns, strict=True)):
        d_top = round(h0 - float(top), 6)
        where = f"{path}: density-profile sample {k} (depth {metres(d_top)} m)"
        th = float("nan") if th is None else float(th)
        if not th > 0.0:
            raise ProfileError(f"{where} thickness", th, "a sample thickness > 0 m")
        if rho is None or not (math.isfinite(float(rho)) and 0.0 < float(rho) <= 917.0):
            raise ProfileError(f"{where} density", rho, "a density in (0, 917] kg/m^3")
        rows.append((d_top, round(d_top + th, 6), float(rho)))
    return np.array(rows, dtype=float).reshape(-1, 3)


def _overlap_means(tops: np.ndarray, bottoms: np.ndarray, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per layer: the length covered by samples and the overlap-weighted mean sample density (nan: none).

    Covered length and mass above depth z are sums of ramps, piecewise linear between the samples'
    ends: built once by a sweep, read at the layer boundaries by interpolation (O((n + m) log m)).
    """
    if len(samples) == 0:
        return np.zeros(len(tops)), np.full(len(tops), np.nan)
    st, sb, rho = samples.T
    z = np.concatenate([st, sb])
    order = np.argsort(z, kind="stable")
    z = z[order]
    slope_c = np.cumsum(np.concatenate([np.ones_like(st), -np.ones_like(sb)])[order])
    slope_m = np.cumsum(np.concatenate([rho, -rho])[order])
    dz = np.diff(z)
    C = np.concatenate([[0.0], np.cumsum(slope_c[:-1] * dz)])
    M = np.concatenate([[0.0], np.cumsum(slope_m[:-1] * dz)])
    covered = np.interp(bottoms, z, C) - np.interp(tops, z, C)
    mass = np.interp(bottoms, z, M) - np.interp(tops, z, M)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(covered > TOLERANCE, mass / np.where(covered > 0, covered, 1.0), np.nan)
    return covered, mean


def _law(hardness: str | None, g1: str | None, g2: str | None, where: str) -> tuple[float | None, str]:
    """Density and its source from hand hardness and grain form (None: the grain has no law)."""
    if hardness is None or g1 is None:
        raise ProfileError(f"{where} density", None, "a measured density, or a hand hardness and a grain form "
                                                     f"for the hardness law (hardness = {hardness!r}, "
                                                     f"grain = {g1!r})")
    if hardness not in HARDNESS_INDEX:
        raise ProfileError(f"{where} hardness", hardness, "a hand hardness: F, 4F, 1F, P, K, I, e.g. '4F-1F', '1F+'")
    for name, grain in (("grain_1", g1), ("grain_2", g2)):
        if grain is not None and grain not in GRAIN_CLASS:
            raise ProfileError(f"{where} {name}", grain, "an IACS grain shape code, e.g. 'RG', 'FCxr', 'SH'")
    for grain in (g1, g2):
        cls = None if grain is None else GRAIN_CLASS[grain]
        if cls is None:
            continue
        fit = GJ_FITS[cls]
        src = f"Geldsetzer and Jamieson 2000 from hardness {hardness} and grain {grain}"
        if cls != grain:
            src += f" (class {cls})"
        if grain != g1:
            src += f", the secondary grain: {g1} has no law"
        lo, hi = (HARDNESS_INDEX[s] for s in fit.hardness_span)
        if not lo <= HARDNESS_INDEX[hardness] <= hi:
            src += f", extrapolated beyond the fit's hardness {fit.hardness_span[0]} to {fit.hardness_span[1]}"
        return geldsetzer_jamieson_density(hardness, grain), src
    grains = "/".join(g for g in (g1, g2) if g)
    return None, f"none: grain {grains} has no Geldsetzer and Jamieson 2000 law and no density was measured"


def _layers(sp, path: str) -> tuple[ProfileLayer, ...]:
    strat = sp.stratigraphy_profile
    if strat is None or strat.data is None or len(strat.data) == 0:
        raise ProfileError("profile", path, "a CAAML profile with a stratigraphy (it has no stratigraphy layers)")
    df, h0 = strat.data, _depth_origin(strat, sp)
    tops = np.round(h0 - np.array(_column(df, "top_height"), dtype=float), 6)
    ths = np.array([np.nan if t is None else float(t) for t in _column(df, "thickness")], dtype=float)
    hard, g1s, g2s = (list(map(_text, _column(df, k))) for k in ("hardness", "grain_1", "grain_2"))
    for i, (top, th) in enumerate(zip(tops, ths, strict=True)):
        where = f"{path}: layer {i} (depth {metres(top)}-{metres(top + th)} m)"
        if not th > 0.0:
            raise ProfileError(f"{where} thickness", float(th), "a layer thickness > 0 m")
        expected = 0.0 if i == 0 else tops[i - 1] + ths[i - 1]
        if abs(top - expected) > TOLERANCE:
            if i == 0:
                raise ProfileError(f"{where} depth_top", float(top), "0 m: the first layer starts at the snow surface")
            kind = "a gap" if top > expected else "an overlap"
            raise ProfileError(f"{where} depth_top", float(top), f"{metres(expected)} m, the bottom of layer {i - 1} "
                               f"({kind} of {metres(abs(top - expected))} m: layers must be contiguous; a gap is not "
                               "filled, its snow was not described)")
    hs = sp.profile_depth
    if hs is not None and hs > 0 and tops[-1] + ths[-1] > hs + TOLERANCE:
        i = len(tops) - 1
        raise ProfileError(f"{path}: layer {i} (depth {metres(tops[i])}-{metres(tops[i] + ths[i])} m) depth_bottom",
                           float(tops[i] + ths[i]), f"at most the snow depth HS = {metres(hs)} m")
    covered, measured = _overlap_means(tops, tops + ths, _samples(sp, path))
    out = []
    for i in range(len(tops)):
        where = f"{path}: layer {i} (depth {metres(tops[i])}-{metres(tops[i] + ths[i])} m)"
        if np.isfinite(measured[i]):
            rho, src = float(measured[i]), MEASURED
        else:
            rho, src = _law(hard[i], g1s[i], g2s[i], where)
        out.append(ProfileLayer(index=i, depth_top=float(tops[i]), thickness=float(round(ths[i], 6)), density=rho,
                                density_source=src, hardness=hard[i], grain_1=g1s[i], grain_2=g2s[i]))
    return tuple(out)


def _psts(sp) -> tuple[PSTRecord, ...]:
    out = []
    for t in sp.stability_tests:
        if getattr(t, "type", None) != "PST":
            continue
        depth = None
        if t.height is not None and sp.profile_depth is not None:
            depth = round(float(sp.profile_depth) - float(t.height), 6)
        out.append(PSTRecord(cut_length=float(t.cut_length), column_length=None if t.column_length is None
                             else float(t.column_length), propagation=t.propagation, depth=depth,
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

    Raises
    ------
    ProfileError
        One line naming the file and, for a bad layer, the layer (index from the top, depth) and the value:
        no such file, not a regular file, too large, not XML, not CAAML, a layer of zero or negative
        thickness, a gap or overlap between layers, a layer with neither a measured density nor a hand
        hardness and a grain form.
    ProfileLibraryMissing
        snowprofile is not installed (the line says how to install it).
    """
    data = read_capped(path)
    path = str(path)
    version = caaml_version(data, path)
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
