"""The plastic-step benchmark scene: a Cam-Clay snow block struck obliquely.

Both engines (mpm_warp and the Taichi peer) run exactly this scene; every number
comes from here.

Physics
-------
The material is the weak layer of ``scenarios/pst_flat.toml``: E = 1 MPa,
nu = 0.3, rho = 150 kg/m^3, M = 1.2, beta = 0.3, xi = 0.0066, consolidated at
p0_ini = 3.7 kPa (three times the normal stress of the PST slab). At rest it is
elastic everywhere. The block ``[0.25, 0.75]^d`` (half-width h = 0.25 m) starts
with the velocity of an oblique strike at V = 10 m/s (avalanche-impact speeds;
the dynamic pressure rho V^2 = 15 kPa is four times p0_ini, so inertia carries
the block far past yield)::

    v_x = (V / h) (y - 0.5)                       simple shear, rate V/h = 40/s
    v_y = -(V / h) (y - 0.5) (x - 0.5) / h        compaction for x > 0.5, extension for x < 0.5

so the half at ``x > 0.5`` is compacted and sheared (its returns land on the
cap, p > p_c, and compact: ``log_Jp`` falls) and the half at ``x < 0.5`` is
pulled apart and sheared (returns on the dry side, p < p_c, with dilation:
``log_Jp`` rises and the material softens). The rate is such that the trial
state leaves the yield surface by a finite strain every step, so the return's
root-finder iterates: one step strains the block by ``(V/h) dt``, about its
initial yield strain p0_ini / K = 4.4e-3 at 32 cells and half of it at 64.
``C`` starts as the exact velocity gradient. Gravity acts as in the elastic
block.

Time step and warm-up
---------------------
``dt = 0.4 dx / (c_p + |v|max)`` (c_p = 95 m/s, |v|max = sqrt(2) V), fixed for
the run. Before timing, both engines step for ``WARMUP_YIELD_TIMES`` times the
time the strike needs to strain the block to its initial yield strain
p0_ini / K, so that the timed steps find the block yielding. The benchmarks
record the return kinds of every timed step (:func:`return_kinds`) and check
that at least ``MIN_YIELDED`` of the particles yield and at least
``MIN_EACH_KIND`` return on the cap and on the dry side
(:func:`check_return_kinds`).
"""

from __future__ import annotations

import math

import numpy as np

#: Young's modulus (Pa): the PST weak layer (pst_flat.toml).
YOUNG_E = 1.0e6
#: Poisson ratio (-).
POISSON_NU = 0.3
#: Density (kg/m^3).
DENSITY = 150.0
#: Critical-state slope (-): a 30 degree friction angle.
M_CSL = 1.2
#: Cohesion ratio (-).
BETA = 0.3
#: Hardening coefficient (-): 20 % collapse under the PST slab.
XI = 0.0066
#: Initial consolidation pressure (Pa).
P0_INI = 3.7e3
#: Floor of p0 relative to K (-), the engine's default (docs/model.md §3).
P0_FLOOR_RATIO = 1.0e-5
#: Speed of the oblique strike at the block's edge (m/s).
IMPACT_SPEED = 10.0
#: Half-width of the block (m).
HALF_WIDTH = 0.25
#: Courant number of the fixed time step (the engine's default).
CFL = 0.4
#: Warm-up length in units of the time to reach the initial yield strain.
WARMUP_YIELD_TIMES = 5.0
#: Gravity (m/s^2), as in the elastic block.
GRAVITY_Y = -9.81


def lame() -> tuple[float, float, float]:
    """``(mu, lam, K)`` of the material (Pa)."""
    mu = YOUNG_E / (2.0 * (1.0 + POISSON_NU))
    lam = YOUNG_E * POISSON_NU / ((1.0 + POISSON_NU) * (1.0 - 2.0 * POISSON_NU))
    return mu, lam, lam + 2.0 * mu / 3.0


def p_wave_speed() -> float:
    """c_p = sqrt((lam + 2 mu) / rho) (m/s)."""
    mu, lam, _ = lame()
    return math.sqrt((lam + 2.0 * mu) / DENSITY)


def initial_log_jp() -> float:
    """``log_Jp(0) = -asinh(p0_ini / K) / xi`` (docs/model.md §3)."""
    return -math.asinh(P0_INI / lame()[2]) / XI


def strain_rate() -> float:
    """Shear and compaction rate V / h (1/s)."""
    return IMPACT_SPEED / HALF_WIDTH


#: Smallest grid: below it the block's stencil reaches the slip-wall layer three cells in from the
#: box edge (mpm_warp and Taichi mark those layers one node apart) and the engines stop being comparable.
MIN_N_GRID = 24


def check_n_grid(n_grid: int) -> int:
    """Return ``n_grid`` if the scene fits (even, >= MIN_N_GRID); raise ValueError naming it otherwise."""
    if n_grid < MIN_N_GRID or n_grid % 2:
        raise ValueError(f"n_grid = {n_grid}: the plastic block needs an even n_grid >= {MIN_N_GRID}")
    return n_grid


def time_step(n_grid: int) -> float:
    """Fixed step ``CFL dx / (c_p + sqrt(2) V)`` (s) of a unit box with ``n_grid`` cells."""
    return CFL * (1.0 / n_grid) / (p_wave_speed() + math.sqrt(2.0) * IMPACT_SPEED)


def warmup_steps(n_grid: int) -> int:
    """Untimed steps before the timing: ``WARMUP_YIELD_TIMES`` times (p0_ini / K) / rate."""
    t_yield = P0_INI / lame()[2] / strain_rate()
    return max(1, math.ceil(WARMUP_YIELD_TIMES * t_yield / time_step(n_grid)))


def initial_velocity(x: np.ndarray) -> np.ndarray:
    """Velocity (m/s) of the strike at positions ``x`` (n, d), d = 2 or 3; float64."""
    x = np.asarray(x, dtype=np.float64)
    rate = strain_rate()
    y = x[:, 1] - 0.5
    s = (x[:, 0] - 0.5) / HALF_WIDTH
    v = np.zeros_like(x)
    v[:, 0] = rate * y
    v[:, 1] = -rate * y * s
    return v


def initial_velocity_gradient(x: np.ndarray) -> np.ndarray:
    """Exact ``C = grad v`` (1/s), (n, d, d), of :func:`initial_velocity`; float64."""
    x = np.asarray(x, dtype=np.float64)
    n, d = x.shape
    rate = strain_rate()
    C = np.zeros((n, d, d))
    C[:, 0, 1] = rate
    C[:, 1, 0] = -rate * (x[:, 1] - 0.5) / HALF_WIDTH
    C[:, 1, 1] = -rate * (x[:, 0] - 0.5) / HALF_WIDTH
    return C


def return_kinds(log_jp_before: np.ndarray, log_jp_after: np.ndarray, yielded: np.ndarray) -> dict:
    """Fractions of the particles whose return was active in one step, by kind.

    A cap return compacts (``log_Jp`` falls: the trial pressure lay beyond the
    ellipse and the return lowered it); a dry-side return dilates (``log_Jp``
    rises). Returns ``{"yielded", "cap", "dry"}`` as fractions of all particles.
    """
    y = np.asarray(yielded).astype(bool)
    d = np.asarray(log_jp_after, dtype=np.float64) - np.asarray(log_jp_before, dtype=np.float64)
    n = max(len(y), 1)
    return {"yielded": float(y.sum() / n), "cap": float((y & (d < 0)).sum() / n),
            "dry": float((y & (d > 0)).sum() / n)}


#: Every timed step must have at least this fraction yielding, and this fraction of each return kind.
MIN_YIELDED = 0.9
MIN_EACH_KIND = 0.05


def check_return_kinds(per_step: list[dict]) -> list[str]:
    """Problems with the per-step return fractions (empty when the scene did its job)."""
    bad = []
    for k, r in enumerate(per_step):
        if r["yielded"] < MIN_YIELDED:
            bad.append(f"step {k}: yielded fraction {r['yielded']:.3f} < {MIN_YIELDED}")
        for kind in ("cap", "dry"):
            if r[kind] < MIN_EACH_KIND:
                bad.append(f"step {k}: {kind} fraction {r[kind]:.3f} < {MIN_EACH_KIND}")
    return bad


def stress_invariants(F: np.ndarray, F_zz: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Kirchhoff ``p = -K tr eps`` and ``q = sqrt(6) mu |dev eps|`` (Pa) from ``F_E`` on the host.

    ``F`` is (n, 3, 3), or (n, 2, 2) with ``F_zz`` the out-of-plane elastic
    stretch (plane strain; ``None`` means 1). Hencky strains from the
    eigenvalues of ``F F^T`` in float64, independent of either engine.
    """
    F = np.asarray(F, dtype=np.float64)
    b = F @ np.transpose(F, (0, 2, 1))
    lam_b = np.linalg.eigvalsh(b)
    eps = 0.5 * np.log(np.maximum(lam_b, 1e-300))
    if F.shape[1] == 2:
        fz = np.ones(len(F)) if F_zz is None else np.asarray(F_zz, dtype=np.float64)
        eps = np.concatenate([eps, np.log(fz)[:, None]], axis=1)
    mu, _, K = lame()
    tr = eps.sum(axis=1)
    dev = eps - tr[:, None] / 3.0
    return -K * tr, math.sqrt(6.0) * mu * np.sqrt((dev * dev).sum(axis=1))


def observables(F, log_jp, F_zz=None) -> dict:
    """Physical observables compared between the engines after the same steps.

    ``mean_p``, ``mean_q`` (Pa), ``mean_log_jp`` and ``mean_abs_dlog_jp`` (mean
    |log_Jp - log_Jp(0)|, the plastic volume change of either sign).
    """
    p, q = stress_invariants(F, F_zz)
    lj = np.asarray(log_jp, dtype=np.float64)
    return {"mean_p": float(p.mean()), "mean_q": float(q.mean()), "mean_log_jp": float(lj.mean()),
            "mean_abs_dlog_jp": float(np.abs(lj - initial_log_jp()).mean())}


#: Largest allowed engine difference of each observable, as a fraction of its scale: mean p and mean q
#: against p0_ini (3.7 Pa: the two engines take different float32 paths, series or SVD strain and a
#: corrected or rebuilt F_E, and one float32 unit of strain is 0.05 Pa of pressure, summed over ~100
#: steps of returns), log_Jp against the mean plastic volume change.
AGREEMENT = 1.0e-3


def agreement(a: dict, b: dict) -> dict:
    """Scaled differences of the observables of two engines and whether all are within :data:`AGREEMENT`."""
    scale = {"mean_p": P0_INI, "mean_q": P0_INI,
             "mean_log_jp": max(a["mean_abs_dlog_jp"], 1e-12), "mean_abs_dlog_jp": max(a["mean_abs_dlog_jp"], 1e-12)}
    diff = {k: abs(a[k] - b[k]) / scale[k] for k in scale}
    return {"scaled_differences": diff, "tolerance": AGREEMENT, "agree": all(d <= AGREEMENT for d in diff.values())}
