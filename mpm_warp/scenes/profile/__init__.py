"""A snow profile as input: snow properties from what a field profile records.

- :mod:`.density_laws`: density from hand hardness and grain form (Geldsetzer and Jamieson 2000),
  Young's modulus (Bergfeld et al. 2023) and tensile strength (Sigrist 2006) from density.
"""

from __future__ import annotations

from .density_laws import (
    bergfeld_modulus,
    density_class,
    geldsetzer_jamieson_density,
    hardness_index,
    sigrist_tensile_strength,
)

__all__ = ["geldsetzer_jamieson_density", "hardness_index", "density_class", "bergfeld_modulus",
           "sigrist_tensile_strength"]
