"""A field case's outcome as a probability: a first-order reading of its one run under snow's strength scatter.

Snow's tensile strength scatters from sample to sample as a Weibull law of modulus 1.5 (+- 0.5) with no size
effect (Phys. Rev. E 69, 011306, 2004). The run's slab body carried at most ``r`` times its density law's strength
(:func:`slab_reading`: ``slab_peak_body_stress_ratio``, the largest over the frames, 1 where it cracked; the rows
the grid ties to the weak layer are left out, docs/field.md): a slab whose strength is
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

__all__ = ["WEIBULL_MODULUS", "SLAB_READINGS", "weibull_break_probability", "slab_reading", "outcome_probability",
           "record_probabilities", "probability_line"]

#: Weibull modulus of snow's tensile strength (-), Phys. Rev. E 69, 011306 (2004)
WEIBULL_MODULUS = 1.5

#: the slab readings a record or an outcome may carry, the first present taken (:func:`slab_reading`): the body's
#: peak over the run's frames, the body's at the call read from the final checkpoint (a run recorded before the
#: body's series), the whole slab's peak (a run recorded before the body's reading)
SLAB_READINGS = ("slab_peak_body_stress_ratio", "slab_body_stress_ratio_at_call", "slab_peak_stress_ratio")


def slab_reading(rec: dict) -> tuple[float | None, str | None]:
    """``(r, key)``: the first finite reading of :data:`SLAB_READINGS` in ``rec`` (a record or an outcome), and its
    key; ``(None, None)`` without one."""
    for key in SLAB_READINGS:
        r = rec.get(key)
        if isinstance(r, (int, float)) and r == r:
            return float(r), key
    return None, None


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


def record_probabilities(rec: dict) -> None:
    """Set a field record's ``p_end``, ``p_sf``, ``p_arr`` from its ``predicted`` class and its slab's reading
    (:func:`slab_reading`); a record without a probability is left as it is."""
    prob = outcome_probability(rec.get("predicted"), slab_reading(rec)[0])
    if prob is not None:
        rec["p_end"], rec["p_sf"], rec["p_arr"] = prob


def probability_line(outcome: dict) -> str:
    """``  P(END) 0.63, P(SF) 0.37, P(ARR) 0.00 (...)`` and a newline for a PST run's ``outcome`` (its class and
    its slab's reading, :func:`slab_reading`), or "" where it has no probability (a slab that cannot break, a run
    not decided)."""
    r, key = slab_reading(outcome)
    p = outcome_probability(outcome.get("class"), r)
    if p is None:
        return ""
    what = "the slab body's peak stress" if "body" in key else "the slab's peak stress"
    return (f"  P(END) {p[0]:.2f}, P(SF) {p[1]:.2f}, P(ARR) {p[2]:.2f} ({what} {r:.2f} x its strength, under "
            "snow's Weibull strength scatter)\n")
