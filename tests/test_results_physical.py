"""Every committed results file (``benchmarks/*/results/**/*.json``) holds numbers physics allows: no inf or
NaN anywhere (a value that does not exist is null, with its reason under ``<key>_null``), and no front speed
above the slab's P-wave speed outside a part that says "nucleation ahead of the front" (issue 37)."""

from __future__ import annotations

import glob
import json
import math
import os
import re

import pytest

from mpm_warp.scenes.front_speed import NUCLEATION

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = sorted(glob.glob(os.path.join(ROOT, "benchmarks", "*", "results", "**", "*.json"), recursive=True))
#: a key holding a front speed (m/s): ``speed``, ``damage_speed_max``, ``early_speed``, ... (not ``speedup``, nor
#: ``speed_mean_over`` (positions) or a ``*_null`` reason)
SPEED_KEY = re.compile(r"(^|_)speed(_mean|_max|_run)?$")
#: c_p / c_s of the project's slabs (nu = 0.3): sqrt(2 (1 - nu) / (1 - 2 nu))
CP_OVER_CS = math.sqrt(2 * 0.7 / 0.4)
#: c_p (m/s) where a file names no slab wave speed: the slab of pst_flat/pst_slope and the ladder PST
#: (E 5 MPa, nu 0.3, 250 kg/m^3), the stiffest slab of the studies that do not store one
DEFAULT_CP = 164.08

def _numbers(path: str):
    """The file's JSON and the non-finite tokens (NaN, Infinity) it holds."""
    bad = []
    with open(path) as fh:
        data = json.load(fh, parse_constant=lambda c: bad.append(c) or math.nan)
    return data, bad


def _bound(d: dict, parent: float) -> float:
    cp = d.get("p_wave_speed")
    if isinstance(cp, (int, float)) and math.isfinite(cp):
        return float(cp)
    cs = d.get("shear_wave_speed")
    if isinstance(cs, (int, float)) and math.isfinite(cs):
        return CP_OVER_CS * float(cs)
    return parent


def _speeds_over(obj, cp: float, where: str, out: list) -> None:
    """Append ``(where, value, c_p)`` for every front speed above ``c_p`` outside a nucleation part."""
    if isinstance(obj, dict):
        if any(isinstance(v, str) and NUCLEATION in v for v in obj.values()):
            return
        cp = _bound(obj, cp)
        for k, v in obj.items():
            if isinstance(k, str) and SPEED_KEY.search(k) and "wave" not in k and not k.endswith("_null"):
                vals = v if isinstance(v, list) else [v]
                out += [(f"{where}.{k}", x, cp) for x in vals if isinstance(x, (int, float))
                        and not isinstance(x, bool) and not x <= cp]
            if isinstance(v, (dict, list)):
                _speeds_over(v, cp, f"{where}.{k}", out)
    elif isinstance(obj, list):
        for x in obj:
            _speeds_over(x, cp, f"{where}[]", out)


def test_there_are_results_to_check():
    names = {os.path.relpath(f, ROOT) for f in FILES}
    assert {"benchmarks/snow/results/snow_pst_slope.json", "benchmarks/snow/results/snow_pst_flat.json"} <= names
    assert len(FILES) >= 30


@pytest.mark.parametrize("path", FILES, ids=lambda p: os.path.relpath(p, ROOT))
def test_committed_result_is_finite_and_slower_than_sound(path):
    rel = os.path.relpath(path, ROOT)
    data, bad = _numbers(path)
    assert not bad, f"{rel} holds {len(bad)} non-finite numbers ({sorted(set(bad))}): write it through " \
                    "mpm_warp.finite_json (null with its reason)"
    over = []
    _speeds_over(data, DEFAULT_CP, "", over)
    assert not over, f"{rel}: speeds above c_p outside '{NUCLEATION}': {over[:5]}"


def test_the_check_catches_what_the_slope_file_held():
    # the profile pst_slope.json held before its reanalysis (c_p 164 m/s): 212, 365, 1659 m/s and 7.5e15 m/s
    old = {"result": {"shear_wave_speed": 87.7058, "damage_speed_profile": {"s": [7.05, 7.3, 7.55],
                                                                             "speed": [212.37, 364.88, 1659.4]},
                      "deflection_speed_max": 139.9, "deflection_speed_profile": {"speed": [7.5e15, 30.0]}}}
    over = []
    _speeds_over(old, DEFAULT_CP, "", over)
    assert [v for _, v, _ in over] == [212.37, 364.88, 1659.4, 7.5e15]
    assert all(cp == pytest.approx(164.08, rel=1e-4) for _, _, cp in over)
    # the same numbers inside a part marked as nucleation are not speeds
    marked = {"nucleation_apparent_speed": {"note": NUCLEATION + ": not a speed", "speed": [1659.4]}, "speedup": 5e3}
    over2 = []
    _speeds_over(marked, DEFAULT_CP, "", over2)
    assert over2 == []
