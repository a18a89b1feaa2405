"""What the weak layer's along-slope scatter could stop: a first-order upper bound on a field column's P(ARR).

A weak layer's shear strength varies along a slope, by a coefficient of variation of 14-18 % over Jamieson and
Johnston's 2001 shear-frame sets; Gaume et al. 2013 model it as a Gaussian random field with a spherical
covariance. Beyond the cut where the column's crack starts, weac's energy release rate ``G(x)`` (J/m^2) meets a
fracture energy ``w_f(x) = w_f (1 + c z(x))^2``, with ``z`` the unit field conditioned on ``z = 0`` at the start
(the layer there is the one the recorded cut reads back). The scatter is documented at the scale of its
measurement, a 250 cm^2 shear frame, so the field is read at points one frame's side apart: the crack stops at
the first where ``w_f(x) > G(x)``. Read finer, a field this rough stops every crack at its start as the spacing
goes to 0, an answer of the spacing and not of the snow. Every other choice leans towards arrest, so the
probability bounds what the documented scatter can do: a static balance (no kinetic energy in the running
crack), the exponent 2 (a cohesive layer's energy to its peak at a fixed stiffness), the lesser of weac's G with
and without touchdown, the upper end of the scatter. docs/field.md, "What could stop the crack (ARR)".
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["STRENGTH_CV", "CORRELATION_LENGTHS", "FRACTURE_ENERGY_EXPONENT", "GRID_M", "spherical_correlation",
           "conditioned_covariance", "arrest_probability", "release_profile", "column_arrest", "FRAME_SIDE_M"]

#: the weak layer's strength scatter along a slope (-): the upper end of 14-18 % (Jamieson and Johnston 2001)
STRENGTH_CV = 0.18
#: correlation lengths (m) the study brackets: no field study pins it at a column's scale (Kronholm and Schweizer
#: 2003 found the stability tests' autocorrelation but no range on their arrays of metres)
CORRELATION_LENGTHS = (0.1, 0.3, 1.0, 3.0)
#: w_f scales as the strength to this power (a cohesive layer's elastic energy to its peak, fixed stiffness)
FRACTURE_ENERGY_EXPONENT = 2.0
#: m: the side of the 250 cm^2 shear frame the strength's scatter was measured with (Jamieson and Johnston 2001)
FRAME_SIDE_M = math.sqrt(0.025)
#: m: spacing of the points along the column where the balance is read: the frame's side
GRID_M = FRAME_SIDE_M
#: m: the balance is read up to this far from the far end (where the cut column's last strip lets go)
FAR_END_M = 0.05
#: cuts at which weac's G is solved between the start and the far end (denser near the start)
PROFILE_POINTS = 24


def spherical_correlation(d, xi: float) -> np.ndarray:
    """The spherical correlation ``1 - 1.5 d/xi + 0.5 (d/xi)^3`` for ``d < xi``, 0 beyond (``d``, ``xi`` in m)."""
    r = np.minimum(np.abs(np.asarray(d, dtype=float)) / xi, 1.0)
    return 1.0 - 1.5 * r + 0.5 * r**3


def conditioned_covariance(x, start: float, xi: float) -> np.ndarray:
    """The unit field's covariance at the points ``x`` (m) given ``z(start) = 0``:
    ``rho(x_i - x_j) - rho(x_i - start) rho(x_j - start)``."""
    x = np.asarray(x, dtype=float)
    r0 = spherical_correlation(x - start, xi)
    return spherical_correlation(x[:, None] - x[None, :], xi) - np.outer(r0, r0)


def arrest_probability(x, g, start: float, xi: float, *, cv: float = STRENGTH_CV, samples: int = 4000,
                       seed: int = 0, exponent: float = FRACTURE_ENERGY_EXPONENT) -> float:
    """The share of ``samples`` weak layers (seeded) whose fracture energy over its value at ``start`` exceeds
    ``g`` (weac's G over that value, -) at one of the points ``x`` (m, beyond ``start``): the crack's arrest."""
    x, g = np.asarray(x, dtype=float), np.asarray(g, dtype=float)
    w, v = np.linalg.eigh(conditioned_covariance(x, start, xi))
    z = (v * np.sqrt(np.clip(w, 0.0, None))) @ np.random.default_rng(seed).standard_normal((len(x), int(samples)))
    wf = np.clip(1.0 + cv * z, 0.0, None) ** exponent
    return float(np.mean((wf > g[:, None]).any(axis=0)))


def release_profile(column, w_f: float, start: float, *, grid: float = GRID_M, points: int = PROFILE_POINTS,
                    far_end: float = FAR_END_M) -> tuple[np.ndarray, np.ndarray, int] | None:
    """``(x, G/w_f, n)``: weac's G (the lesser with and without touchdown) over ``w_f`` at the points of
    ``grid`` (m) from ``start`` (exclusive) to ``far_end`` before the end of ``column`` (a
    :class:`~mpm_warp.scenes.pst.static.StaticColumn`), interpolated in log between ``points`` solved cuts that
    crowd towards the start; ``n``: the solved cuts where weac's touchdown has no solution (its root search finds
    no touchdown length), which take the free slab's G; None where no point lies between."""
    from ..scenes.weac_reference import energy_release_rate

    end = column.length - far_end
    if end - start < grid:
        return None
    cuts = start + (end - start) * np.linspace(0.0, 1.0, points) ** 2
    G, untouched = [], 0
    for a in cuts:
        free = energy_release_rate(column, float(a))[0]
        try:
            G.append(min(free, energy_release_rate(column, float(a), touchdown=True)[0]))
        except ValueError:                      # weac finds no touchdown length at this cut: the free slab's G
            G.append(free)
            untouched += 1
    x = start + grid * np.arange(1, int(math.floor((end - start) / grid)) + 1)
    return x, np.exp(np.interp(x, cuts, np.log(np.maximum(G, 1e-300) / w_f))), untouched


def column_arrest(params, w_f: float, cut: float, *, xis=CORRELATION_LENGTHS, cv: float = STRENGTH_CV,
                  grid: float = GRID_M, samples: int = 4000, seed: int = 0) -> dict:
    """A field column's (PSTParams) arrest bound at each correlation length of ``xis`` (m), its crack starting at
    the recorded ``cut`` (m) where weac's G there reaches ``w_f`` (J/m^2), else at weac's critical cut; the field
    read every ``grid`` (m).

    Returns ``{"start": m, "touchdown_unsolved": n, "g_at_10cm": G/w_f 10 cm past the start, "g_min": the least
    G/w_f at the points read, "p_arr": {xi: P}}`` (``n``: :func:`release_profile`; ``g_min`` below 1: weac's
    static balance with touchdown stops the crack in a uniform layer, Rosendahl et al. 2025), or
    ``{"why": line}`` where weac is missing or the crack never starts or has no room to stop."""
    from ..scenes.pst.static import static_column
    from ..scenes.weac_reference import critical_cut_search, energy_release_rate, weac_unavailable

    why = weac_unavailable()
    if why is not None:
        return {"why": why}
    col = static_column(params)
    start = float(cut)
    if energy_release_rate(col, start)[0] < w_f:
        found = critical_cut_search(col, w_f, max_cut=col.length - FAR_END_M)
        if found.value is None:
            return {"why": f"no propagation: {found.reason}"}
        start = float(found.value)
    prof = release_profile(col, w_f, start, grid=grid)
    if prof is None:
        return {"why": f"the crack starts at {start:.3f} m, within {FAR_END_M + grid:.2f} m of the far end"}
    x, g, untouched = prof
    ahead = start + 0.1
    return {"start": start, "touchdown_unsolved": untouched, "g_min": float(g.min()),
            "g_at_10cm": float(energy_release_rate(col, ahead)[0] / w_f) if ahead < col.length else None,
            "p_arr": {float(xi): arrest_probability(x, g, start, xi, cv=cv, samples=samples, seed=seed)
                      for xi in xis}}
