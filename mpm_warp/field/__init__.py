"""Field data in: real snow pits' PST records as runnable columns, or refused in one line in field terms.

- :func:`~.cases.field_cases`: a CAAML file's PST records, each a :class:`~.cases.FieldCase` (the column,
  calibrated, with the fracture energy the record implies) or a :class:`~.cases.FieldRefusal`.
- :func:`~.fracture_energy.implied_fracture_energy`: w_f from a recorded cut, only where a cut can be read.
- :func:`~.census.census`: a folder of pits counted by outcome and by refusal reason.

This package sits above the scenes (it builds PST scenes from field records) and below the command line.
"""

from .cases import FieldCase, FieldRefusal, field_case, field_cases
from .fracture_energy import ImpliedFractureEnergy, implied_fracture_energy

__all__ = ["FieldCase", "FieldRefusal", "field_case", "field_cases", "ImpliedFractureEnergy",
           "implied_fracture_energy"]
