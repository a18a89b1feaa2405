"""A field case's outcome as a probability: a first-order reading of its one run under snow's strength scatter.

Snow's tensile strength scatters from sample to sample as a Weibull law of modulus 1.5 (+- 0.5) with no size
effect (Phys. Rev. E 69, 011306, 2004). The run's slab carried at most ``r`` times its density law's strength
(``slab_peak_stress_ratio``, the largest over the frames; 1 where it cracked): a slab whose strength is
drawn below ``r`` times the law's breaks. Taking the law as the distribution's mean, ``P(SF) = 1 - exp(-(r
Gamma(1 + 1/m))^m)`` with ``r`` capped at 1, since a crack that formed says the stress reached the strength and
not how far beyond it a stronger slab would have been loaded. The rest goes to the run's own class (END for a
run whose slab broke: a stronger slab would not have stopped the crack; ARR for a crack that stopped in the weak
layer, NP included, which the observer sees as the same). docs/field.md, "The outcome as a probability", says
what this reading leaves out (the weak layer's along-slope scatter needs an ensemble).
"""

from __future__ import annotations

import math

from ..scenes.pst.outcome import CLASSES

__all__ = ["WEIBULL_MODULUS", "weibull_break_probability", "outcome_probability", "probability_line"]

#: Weibull modulus of snow's tensile strength (-), Phys. Rev. E 69, 011306 (2004)
WEIBULL_MODULUS = 1.5


def weibull_break_probability(ratio: float, modulus: float = WEIBULL_MODULUS) -> float:
    """The probability that a Weibull strength whose mean is the law's lies below ``ratio`` times the law's (-)."""
    if not ratio > 0.0:
        return 0.0
    return 1.0 - math.exp(-((ratio * math.gamma(1.0 + 1.0 / modulus)) ** modulus))


def outcome_probability(predicted: str | None, slab_peak_stress_ratio: float | None,
                        modulus: float = WEIBULL_MODULUS) -> tuple[float, float, float] | None:
    """``(P(END), P(SF), P(ARR))`` of a run that ended as ``predicted`` with the slab's peak stress over its
    strength ``slab_peak_stress_ratio`` (module docstring); None for a run without a field class or a ratio
    (an older record, "running", failed)."""
    r = slab_peak_stress_ratio
    if predicted not in CLASSES or not isinstance(r, (int, float)) or not r == r:
        return None
    p_sf = weibull_break_probability(min(float(r), 1.0), modulus)
    if predicted in ("ARR", "NP"):
        return 0.0, p_sf, 1.0 - p_sf
    return 1.0 - p_sf, p_sf, 0.0


def probability_line(outcome: dict) -> str:
    """``  P(END) 0.63, P(SF) 0.37, P(ARR) 0.00 (...)`` and a newline for a PST run's ``outcome`` (its class and
    ``slab_peak_stress_ratio``), or "" where it has no probability (a slab that cannot break, a run not decided)."""
    p = outcome_probability(outcome.get("class"), outcome.get("slab_peak_stress_ratio"))
    if p is None:
        return ""
    return (f"  P(END) {p[0]:.2f}, P(SF) {p[1]:.2f}, P(ARR) {p[2]:.2f} (the slab's peak stress "
            f"{outcome['slab_peak_stress_ratio']:.2f} x its strength, under snow's Weibull strength scatter)\n")
