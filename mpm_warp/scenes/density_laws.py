"""Snow properties from what a field profile records: density from hand hardness and grain form;
Young's modulus, tensile strength and fracture toughness from density (docs/model.md §8-9).

- :func:`geldsetzer_jamieson_density`: Geldsetzer and Jamieson (2000), "Estimating dry snow density
  from grain form and hand hardness", Proc. ISSW 2000, Big Sky, 121-127: linear fits of density
  against the hand-hardness index per grain class (their Table 3), a power law for rounded grains
  (their Eq. 5). The table of coefficients and the mapping of every IACS grain code to a class are
  in docs/profiles.md.
- :func:`bergfeld_modulus`: Bergfeld et al. (2023), NHESS 23:293, the law weac uses.
- :func:`sigrist_tensile_strength`: Sigrist (2006), ETH Zurich dissertation 16736.
- :func:`fracture_toughness`: the exponent and typical values of Schweizer, Michot and Kirchner (2004).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidArgument

__all__ = ["HARDNESS_INDEX", "GRAIN_CLASS", "GJ_FITS", "GJFit", "hardness_index", "density_class",
           "geldsetzer_jamieson_density", "bergfeld_modulus", "sigrist_tensile_strength", "fracture_toughness",
           "RHO_ICE"]

#: density of ice (kg/m^3) in Sigrist's law; Bergfeld et al. use 916.7
RHO_ICE = 917.0

#: hand-hardness index of every hardness code a field profile writes (Fierz et al. 2009, the ICSSG):
#: F 1, 4F 2, 1F 3, P 4, K 5, I 6; "A-B" (between two grades) is their mean, "A+" / "A-" is A +- 1/3
_GRADES = {"F": 1, "4F": 2, "1F": 3, "P": 4, "K": 5, "I": 6}
HARDNESS_INDEX: dict[str, float] = {
    **{g: float(v) for g, v in _GRADES.items()},
    **{f"{a}-{b}": (va + vb) / 2.0 for (a, va), (b, vb) in zip(list(_GRADES.items())[:-1], list(_GRADES.items())[1:],
                                                                strict=True)},
    **{f"{g}+": v + 1.0 / 3.0 for g, v in _GRADES.items()},
    **{f"{g}-": v - 1.0 / 3.0 for g, v in _GRADES.items()},
}


@dataclass(frozen=True)
class GJFit:
    """One grain class of Geldsetzer and Jamieson (2000): ``rho = a + b h^exponent`` (kg/m^3).

    Attributes
    ----------
    a, b : float
        Coefficients (kg/m^3).
    exponent : float
        1 for the linear fits (their Table 3); 3.15 for rounded grains (their Eq. 5).
    hardness_span : tuple of str
        Softest and hardest hand hardness of the data behind the fit; beyond them the law is
        extrapolated (the density source says so).
    name : str
        The class in words.
    """

    a: float
    b: float
    exponent: float
    hardness_span: tuple[str, str]
    name: str

    def density(self, h: float) -> float:
        """Density (kg/m^3) at hand-hardness index ``h``."""
        return self.a + self.b * h ** self.exponent


#: the classes of Geldsetzer and Jamieson (2000) and their fits
GJ_FITS: dict[str, GJFit] = {
    "PP": GJFit(45.0, 36.0, 1.0, ("F-", "P"), "precipitation particles"),
    "PPgp": GJFit(83.0, 37.0, 1.0, ("F-", "P"), "graupel"),
    "DF": GJFit(65.0, 36.0, 1.0, ("F-", "P+"), "decomposing and fragmented particles"),
    "RG": GJFit(154.0, 1.51, 3.15, ("F", "K+"), "rounded grains"),
    "RGmx": GJFit(91.0, 42.0, 1.0, ("F-", "P+"), "mixed rounded and faceted grains"),
    "FC": GJFit(112.0, 46.0, 1.0, ("F-", "K-"), "faceted crystals"),
    "FCmx": GJFit(56.0, 64.0, 1.0, ("F", "K+"), "mixed faceted and rounded grains"),
    "DH": GJFit(185.0, 25.0, 1.0, ("F", "K"), "depth hoar"),
}

#: the class of Geldsetzer and Jamieson (2000) of every IACS grain code (Fierz et al. 2009);
#: None: the paper has no fit (surface hoar, melt forms, ice formations, machine-made snow)
GRAIN_CLASS: dict[str, str | None] = {
    **{g: "PP" for g in ("PP", "PPco", "PPnd", "PPpl", "PPsd", "PPir", "PPhl", "PPip", "PPrm")},
    "PPgp": "PPgp",
    **{g: "DF" for g in ("DF", "DFdc", "DFbk")},
    **{g: "RG" for g in ("RG", "RGsr", "RGlr", "RGwp")},
    "RGxf": "RGmx",
    **{g: "FC" for g in ("FC", "FCso", "FCsf")},
    "FCxr": "FCmx",
    **{g: "DH" for g in ("DH", "DHcp", "DHpr", "DHch", "DHla", "DHxr")},
    **{g: None for g in ("SH", "SHsu", "SHcv", "SHxr", "MM", "MMrp", "MMci",
                         "MF", "MFcl", "MFpc", "MFsl", "MFcr", "IF", "IFil", "IFic", "IFbi", "IFrc", "IFsc")},
}


def hardness_index(hardness: str, field: str = "hardness") -> float:
    """Hand-hardness index (-) of a hardness code: F 1 ... I 6, "4F-1F" 2.5, "1F+" 3.33.

    Raises :class:`InvalidArgument` naming ``field`` for a code that is not one of the ICSSG's.
    """
    if not isinstance(hardness, str) or hardness not in HARDNESS_INDEX:
        raise InvalidArgument(field, hardness, "a hand hardness: F, 4F, 1F, P, K or I, between two of them "
                              "(e.g. '4F-1F'), or with + or - (e.g. '1F+')")
    return HARDNESS_INDEX[hardness]


def density_class(grain: str, field: str = "grain") -> str | None:
    """The class of Geldsetzer and Jamieson (2000) of an IACS grain code (None: no fit).

    Raises :class:`InvalidArgument` naming ``field`` for a code that is not an IACS grain shape.
    """
    if not isinstance(grain, str) or grain not in GRAIN_CLASS:
        raise InvalidArgument(field, grain, "an IACS grain shape code (Fierz et al. 2009), e.g. 'RG', 'FCxr', 'SH'")
    return GRAIN_CLASS[grain]


def geldsetzer_jamieson_density(hardness: str, grain: str) -> float:
    """Dry-snow density (kg/m^3) from hand hardness and grain form (Geldsetzer and Jamieson 2000).

    Parameters
    ----------
    hardness : str
        Hand hardness code, e.g. "1F", "4F-1F", "P+" (:func:`hardness_index`).
    grain : str
        IACS grain shape code, e.g. "RG", "FCxr" (mapped by :data:`GRAIN_CLASS`).

    Returns
    -------
    float
        ``a + b h^n`` of the grain's class (kg/m^3), ``h`` the hand-hardness index.

    Raises
    ------
    InvalidArgument
        Unknown codes, or a grain the paper has no fit for (SH, MF, IF, MM and their subclasses).
    """
    h = hardness_index(hardness)
    cls = density_class(grain)
    if cls is None:
        raise InvalidArgument("grain", grain, "a grain form with a Geldsetzer and Jamieson (2000) fit: "
                              "PP, DF, RG, FC, DH and their subclasses (dry snow; SH, MF, IF and MM have none)")
    return GJ_FITS[cls].density(h)


def _densities(density, field: str) -> np.ndarray:
    rho = np.asarray(density, dtype=float) if not isinstance(density, (str, bytes)) else np.asarray(np.nan)
    if rho.dtype.kind != "f" or not np.all(np.isfinite(rho)) or np.any(rho <= 0.0) or np.any(rho > RHO_ICE):
        raise InvalidArgument(field, density, f"a density in (0, {RHO_ICE:g}] kg/m^3")
    return rho


def _power_law(density, scale: float, reference: float, exponent: float):
    """``scale (rho / reference)^exponent`` of the checked densities ``density`` (kg/m^3): a float for a number,
    an array for an array (the laws below)."""
    rho = _densities(density, "density")
    value = scale * (rho / reference) ** exponent
    return float(value) if value.ndim == 0 else value


def bergfeld_modulus(density):
    """Young's modulus of snow (Pa) from its density: ``E = 6.5e3 MPa (rho / 916.7)^4.4``.

    Bergfeld et al. (2023), NHESS 23:293, from PST digital image correlation; the law weac uses.

    Parameters
    ----------
    density : float or array_like
        Density (kg/m^3), in (0, 917].

    Returns
    -------
    float or numpy.ndarray
        E (Pa): 14.8 MPa at 230 kg/m^3, 6.5 GPa at 916.7 kg/m^3.
    """
    return _power_law(density, 6.5e9, 916.7, 4.4)


def sigrist_tensile_strength(density):
    """Tensile strength of snow (Pa) from its density: ``sigma_t = 240 kPa (rho / 917)^2.44``.

    Sigrist (2006), ETH Zurich dissertation 16736 (the law weac's ``tensile_strength_slab`` uses).

    Parameters
    ----------
    density : float or array_like
        Density (kg/m^3), in (0, 917].

    Returns
    -------
    float or numpy.ndarray
        Tensile strength (Pa): 240 kPa at 917 kg/m^3, 10.1 kPa at 250 kg/m^3.
    """
    return _power_law(density, 240.0e3, RHO_ICE, 2.44)


def fracture_toughness(density):
    """Mode-I fracture toughness of snow (Pa m^1/2) from its density: ``750 (rho / 200)^2``.

    Schweizer, Michot and Kirchner (2004, Ann. Glaciol. 38) measured ``K_Ic`` with notched cantilever beams at
    100-300 kg/m^3: typically 500-1000 Pa m^1/2, growing with relative density with an exponent of about 2. This
    law takes their exponent and the middle of their typical range at 200 kg/m^3 (docs/model.md §9); a layer's
    fracture energy is then ``K_Ic^2 (1 - nu^2) / E`` (plane strain).

    Parameters
    ----------
    density : float or array_like
        Density (kg/m^3), in (0, 917].

    Returns
    -------
    float or numpy.ndarray
        K_Ic (Pa m^1/2): 750 at 200 kg/m^3, 422 at 150, 1172 at 250.
    """
    return _power_law(density, 750.0, 200.0, 2)
