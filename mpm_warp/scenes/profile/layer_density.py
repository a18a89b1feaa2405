"""A profile layer's density when none was measured: the hardness law, else a grain-type value, else none.

The order (docs/profiles.md, "Densities"):

1. Geldsetzer and Jamieson (2000) from hand hardness and grain form (:mod:`..density_laws`), the primary
   grain first, the secondary where the primary has no law;
2. fallbacks, each flagged (the density source starts with "fallback"):

   - a grain with no hardness law: buried surface hoar 125 kg/m^3, melt forms and ice formations 292 kg/m^3,
     the values weac (Weissgraeber and Rosendahl 2023) uses for them;
   - a grain with a law but no hand hardness recorded: the law at the middle of the hardness range of its
     data (FC: between F- and K-, 1F-);
   - a hardness but no grain recorded: the mean of the laws of all grain classes at that hardness;

3. none, with the reason (neither hardness nor grain, an unknown code, machine-made snow). A layer without a
   density is refused only where the model needs it: in the slab or under the weak layer.
"""

from __future__ import annotations

from ..density_laws import GJ_FITS, GRAIN_CLASS, HARDNESS_INDEX, geldsetzer_jamieson_density

__all__ = ["estimate_density", "GRAIN_TYPE_DENSITY", "GRAIN_TYPE_SOURCE", "FALLBACK"]

#: density (kg/m^3) of the grain forms without a hardness law, as weac's hardness-to-density table gives them
GRAIN_TYPE_DENSITY: dict[str, float] = {
    **{g: 125.0 for g in ("SH", "SHsu", "SHcv", "SHxr")},
    **{g: 292.25 for g in ("MF", "MFcl", "MFpc", "MFsl", "MFcr", "IF", "IFil", "IFic", "IFbi", "IFrc", "IFsc")},
}
GRAIN_TYPE_SOURCE = "fallback: grain-type value for {grain} (weac's table: no hardness law for this grain)"
FALLBACK = "fallback"


def _gj(hardness: str, grain: str, primary: str | None) -> tuple[float, str]:
    cls = GRAIN_CLASS[grain]
    fit = GJ_FITS[cls]
    src = f"Geldsetzer and Jamieson 2000 from hardness {hardness} and grain {grain}"
    if cls != grain:
        src += f" (class {cls})"
    if grain != primary:
        src += f", the secondary grain: {primary} has no law"
    lo, hi = (HARDNESS_INDEX[s] for s in fit.hardness_span)
    if not lo <= HARDNESS_INDEX[hardness] <= hi:
        src += f", extrapolated beyond the fit's hardness {fit.hardness_span[0]} to {fit.hardness_span[1]}"
    return geldsetzer_jamieson_density(hardness, grain), src


def estimate_density(hardness: str | None, grain_1: str | None, grain_2: str | None) -> tuple[float | None, str]:
    """Density (kg/m^3) of a layer with no measured density, and where it comes from (module docstring).

    Parameters
    ----------
    hardness : str or None
        Hand hardness as the field writes it ("4F", "1F+", "4F-1F").
    grain_1, grain_2 : str or None
        Primary and secondary grain shapes (IACS codes).

    Returns
    -------
    (float or None, str)
        The density, or None with the reason in field terms (e.g. "no hand hardness recorded").
    """
    grains = [g for g in (grain_1, grain_2) if g]
    unknown = [g for g in grains if g not in GRAIN_CLASS]
    if unknown:
        return None, f"grain {unknown[0]!r} is not an IACS grain code"
    if hardness is not None and hardness not in HARDNESS_INDEX:
        return None, f"hand hardness {hardness!r} is not one of F, 4F, 1F, P, K, I (with + - or a range)"
    with_law = [g for g in grains if GRAIN_CLASS[g] is not None]
    if with_law and hardness is not None:
        return _gj(hardness, with_law[0], grain_1)
    for g in grains:
        if g in GRAIN_TYPE_DENSITY:
            return GRAIN_TYPE_DENSITY[g], GRAIN_TYPE_SOURCE.format(grain=g)
    if with_law:                        # no hardness recorded
        fit = GJ_FITS[GRAIN_CLASS[with_law[0]]]
        h = 0.5 * sum(HARDNESS_INDEX[s] for s in fit.hardness_span)
        return fit.density(h), (f"{FALLBACK}: no hand hardness recorded; Geldsetzer and Jamieson 2000 for "
                                f"{with_law[0]} at the middle of its data's hardness, {fit.hardness_span[0]} to "
                                f"{fit.hardness_span[1]}")
    if not grains and hardness is not None:
        h = HARDNESS_INDEX[hardness]
        rho = sum(f.density(h) for f in GJ_FITS.values()) / len(GJ_FITS)
        return rho, (f"{FALLBACK}: no grain form recorded; the mean of Geldsetzer and Jamieson 2000's grain "
                     f"classes at hardness {hardness}")
    if not grains:
        return None, "neither a hand hardness nor a grain form recorded"
    return None, f"grain {'/'.join(grains)} has no density law (machine-made snow)"
