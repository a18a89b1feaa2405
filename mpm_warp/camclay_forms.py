"""Closed forms of the Cam-Clay model on the host (NumPy): the one home of the formulas analyses reuse.

The hardening law's collapse, the yield ellipse through a state, the uniaxial-strain (oedometric) point
on the ellipse and the collapse of a laterally confined layer under a load (docs/model.md §2, §3, §6).
Stresses in Pa, Kirchhoff unless said; compression positive.
"""

from __future__ import annotations

import math

import numpy as np

from .kernels.camclay import initial_log_jp

__all__ = ["hardening_collapse", "consolidation_pressure", "oedometric_ratio", "oedometric_point",
           "oedometric_p0", "oedometric_collapse"]


def hardening_collapse(p, K: float, xi: float, p0_ini: float = 0.0):
    """Plastic collapse ``1 - J_P / J_P,ini`` of Cam-Clay snow consolidated on the cap from ``p0_ini`` to ``p`` (-).

    ``1 - exp(log_Jp(p) - log_Jp(p0_ini))`` with the hardening state of a consolidation
    pressure, ``log_Jp(p0) = -asinh(p0 / K) / xi`` (:func:`mpm_warp.kernels.camclay.initial_log_jp`,
    docs/model.md §3 and §6), i.e. ``1 - exp(-(asinh(p/K) - asinh(p0_ini/K)) / xi)``; zero where
    ``p <= p0_ini`` (the cap does not move below its consolidation pressure). ``p``, ``p0_ini``
    and ``K`` in Pa; ``p`` a float or an array.
    """
    log_jp = np.vectorize(initial_log_jp, otypes=[float])
    c = 1.0 - np.exp(log_jp(p, K, xi) - initial_log_jp(p0_ini, K, xi))
    c = np.where(np.asarray(p, dtype=float) > p0_ini, c, 0.0)
    return float(c) if c.ndim == 0 else c


def consolidation_pressure(p, q, M: float, beta: float):
    """``p0`` (Pa) of the yield ellipse through the Kirchhoff state ``(p, q)`` (Pa).

    The positive root of ``beta M^2 p0^2 + (1 - beta) M^2 p p0 - M^2 p^2 - (1 + 2 beta) q^2 = 0``;
    equals ``p`` when ``q = 0``.
    """
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    b = (1.0 - beta) * p
    c = p * p + (1.0 + 2.0 * beta) * q * q / (M * M)
    if beta == 0.0:
        return c / b
    return (-b + np.sqrt(b * b + 4.0 * beta * c)) / (2.0 * beta)


def oedometric_ratio(M: float, beta: float) -> float:
    """``lambda_oed = max tau_v / p0`` on the yield ellipse (uniaxial strain, xi -> 0); dimensionless.

    The ellipse has centre ``p0 (1 - beta)/2``, semi-axes ``a = p0 (1 + beta)/2``
    in p and ``M a / sqrt(1 + 2 beta)`` in q; the largest ``p + 2 q / 3`` on it is
    ``p0 [(1 - beta) + (1 + beta) sqrt(1 + 4 M^2 / (9 (1 + 2 beta)))] / 2``.
    """
    return 0.5 * ((1.0 - beta) + (1.0 + beta) * math.sqrt(1.0 + 4.0 * M * M / (9.0 * (1.0 + 2.0 * beta))))


def oedometric_point(M: float, beta: float) -> tuple[float, float]:
    """``(p / p0, q / p0)`` of the uniaxial-strain state on the ellipse (xi -> 0)."""
    a = 0.5 * (1.0 + beta)
    b = M * a / math.sqrt(1.0 + 2.0 * beta)
    s = math.sqrt(a * a + (2.0 / 3.0) ** 2 * b * b)
    return 0.5 * (1.0 - beta) + a * a / s, (2.0 / 3.0) * b * b / s


def oedometric_p0(collapse, W, M: float, beta: float, K: float):
    """``p0`` (Pa) on the oedometric point of a layer collapsed by ``collapse`` (-) under the Cauchy load ``W`` (Pa).

    Kirchhoff ``tau_v = J W``, ``J = J_E (1 - collapse)``, ``J_E = exp(-p/K)``, ``tau_v = lambda_oed p0``
    (:func:`oedometric_ratio`, ``p = p0 (p/p0)_oed``): a fixed point in ``J_E`` (50 iterations; floats or arrays).
    """
    lam_oed = oedometric_ratio(M, beta)
    p_over = oedometric_point(M, beta)[0]
    p0 = (1.0 - collapse) * W / lam_oed
    for _ in range(50):
        p0 = np.exp(-p0 * p_over / K) * (1.0 - collapse) * W / lam_oed
    return p0


def oedometric_collapse(W, M: float, beta: float, K: float, xi: float, p0_ini: float = 0.0):
    """Collapse ``1 - J_P/J_P(0)`` of a laterally confined layer at rest under the Cauchy load ``W`` (Pa).

    The fixed point ``c = hardening_collapse(oedometric_p0(c))`` by bisection (100 steps); zero where the
    load stays inside the initial ellipse (``p0 <= p0_ini``). ``W`` a float or an array.
    """
    W = np.asarray(W, dtype=np.float64)
    lo, hi = np.zeros_like(W), np.ones_like(W)
    for _ in range(100):
        c = 0.5 * (lo + hi)
        over = c > hardening_collapse(oedometric_p0(c, W, M, beta, K), K, xi, p0_ini)
        hi = np.where(over, c, hi)
        lo = np.where(over, lo, c)
    c = 0.5 * (lo + hi)
    return float(c) if c.ndim == 0 else c
