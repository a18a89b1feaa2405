"""A snow profile as input: a CAAML file into layer records, the weak layer named by depth or index.

- :func:`read_profile` (:mod:`.caaml`): a CAAML 5 or 6 XML profile into a :class:`SnowProfileData`
  (layers top to bottom with depth, thickness, density and its source, hardness and grains; the
  slope, aspect, site, date, snow depth and PST results). Needs the optional ``snowprofile``
  library (``pip install 'mpm-warp[profile]'``), imported only when a file is read.
- :func:`select_weak_layer` (:mod:`.selection`): the slab above, the weak layer, the layers below.
- :mod:`..density_laws`: density from hand hardness and grain form (Geldsetzer and Jamieson 2000),
  Young's modulus (Bergfeld et al. 2023) and tensile strength (Sigrist 2006) from density.
- :mod:`.example`: the project's own CAAML example, :func:`example_path`.

The library choice, the density law's coefficients and grain classes, and what is refused: docs/profiles.md.
"""

from __future__ import annotations

from ..density_laws import (
    bergfeld_modulus,
    density_class,
    geldsetzer_jamieson_density,
    hardness_index,
    sigrist_tensile_strength,
)
from .caaml import read_profile
from .records import ProfileError, ProfileLayer, ProfileLibraryMissing, PSTRecord, SnowProfileData
from .selection import select_weak_layer

__all__ = ["read_profile", "select_weak_layer", "SnowProfileData", "ProfileLayer", "PSTRecord", "ProfileError",
           "ProfileLibraryMissing", "geldsetzer_jamieson_density", "hardness_index", "density_class",
           "bergfeld_modulus", "sigrist_tensile_strength", "write_example", "example_path", "example_bytes"]


def __getattr__(name):
    # the example module is loaded on use, so that `python -m mpm_warp.scenes.profile.example` runs it fresh
    if name in ("write_example", "example_path", "example_bytes"):
        from . import example
        return getattr(example, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
