"""Weak layer under a slab: the uniaxial-strain closed form of the hardening rule and its engine run."""

from __future__ import annotations

import math

import numpy as np

from .. import camclay_forms as forms
from ..config import Block, Domain, Output, Scenario, TimeControl
from ..materials import CamClaySnow, Elastic
from ..simulation import Simulation
from ..stress import kirchhoff_stress, pressure_and_mises
from ..walls import Wall
from .common import G, _cells, _record


# ------------------------------------------------- weak layer: closed form
def oedometric_collapse(W, mat: CamClaySnow) -> np.ndarray:
    """Closed-form collapse ``1 - J_P`` of a laterally confined layer of ``mat`` under the Cauchy load ``W`` (Pa):
    :func:`mpm_warp.camclay_forms.oedometric_collapse` (derivation in ``tests/test_weak_layer.py``); an array."""
    return np.atleast_1d(forms.oedometric_collapse(W, mat.M, mat.beta, mat.bulk, mat.xi, mat.p0_ini))


def oedometric_state(mat: CamClaySnow, axial_strain: float, n: int = 20000, dtype: str = "float64") -> dict:
    """Uniaxial-strain compaction of one material point with the engine's return (no grid).

    Compresses ``y`` by the logarithmic strain ``axial_strain`` in ``n`` equal
    increments (material-point driver, docs/model.md §4); returns the final ``p, q,
    p0`` (Kirchhoff, Pa), ``e = -(log_Jp - log_Jp(0))`` and ``tau_v = p + 2 q/3`` (Pa).
    """
    from ..material_point import drive_material_points

    step = np.diag([1.0, math.exp(-axial_strain / n), 1.0])
    out = drive_material_points(np.repeat(step[None], n, axis=0), E=mat.E, nu=mat.nu, M=mat.M, beta=mat.beta,
                                xi=mat.xi, p0_ini=mat.p0_ini, dtype=dtype)
    p, q = float(out["p"][0, -1]), float(out["q"][0, -1])
    return {"p": p, "q": q, "p0": float(out["p0"][0, -1]), "tau_v": p + 2.0 * q / 3.0,
            "e": float(out["log_jp"][0, 0] - out["log_jp"][0, -1])}


# --------------------------------------------------- weak layer: set-up, run
def weak_layer_column(*, dx: float, xi: float, rho_slab: float, p0_ini: float = 0.0, D_wl: float = 1.0 / 32.0,
                      h_slab: float = 1.0 / 16.0, E_wl: float = 2.0e5, rho_wl: float = 150.0,
                      E_slab: float = 1.0e6, nu: float = 0.3, M: float = 1.0, beta: float = 0.3,
                      ramp: float = 0.1, ppc: int = 2, cfl: float = 0.4, dt: float | None = None,
                      precision: str = "float32") -> tuple[Scenario, CamClaySnow, dict]:
    """Slab on a weak layer in a one-cell column with slip side walls and a sticky floor.

    Use a binary ``dx`` (1/64, 1/128, ...) so that the box faces lie exactly on
    grid nodes. Gravity ramps over ``ramp`` (s). The slab on the compacting
    layer is one mass-spring of stiffness per area ``k = (lambda_oed xi
    sqrt(K^2 + p0^2) + tau_v) / (J D_wl)``, stiffening from the start to the
    closed-form end state; the grid damping is ``2 omega_end`` (critical at the
    end, overdamped before: an overshoot would compact the layer for good) and
    leaves the static state unchanged. ``time.end`` is a safe upper bound;
    :func:`run_column` stops once the layer has settled.

    Returns ``(scenario, weak-layer material, info)``; ``info`` holds ``W_slab``
    (Pa), ``omega_start``, ``omega_end`` (rad/s), ``damping`` (1/s), ``end`` (s),
    ``collapse_theory`` (closed form under the slab weight) and the geometry (m).
    """
    wl = CamClaySnow(E_wl, nu, rho_wl, M=M, beta=beta, xi=xi, p0_ini=p0_ini)
    slab = Elastic(E_slab, nu, rho_slab)
    H = D_wl + h_slab
    W_slab = rho_slab * G * h_slab
    lam_oed = forms.oedometric_ratio(M, beta)
    K = wl.bulk
    m = rho_slab * h_slab + rho_wl * D_wl / 3.0
    k_start = lam_oed * (xi * math.hypot(K, p0_ini) + p0_ini) / D_wl
    c_end = float(oedometric_collapse(W_slab, wl)[0])
    J_end = 1.0 - c_end
    p0_end = J_end * W_slab / lam_oed
    k_end = (lam_oed * xi * math.hypot(K, p0_end) + J_end * W_slab) / (J_end * J_end * D_wl)
    omega_start = math.sqrt(min(k_start, k_end) / m)
    omega_end = math.sqrt(max(k_start, k_end) / m)
    damping = 2.0 * omega_end
    end = ramp + 6.0 * damping / omega_start**2 + 10.0 * damping / omega_end**2
    n_frames = max(10, math.ceil(end / 0.01))
    sc = Scenario(
        name="weak_layer_column",
        domain=Domain((0.0, 0.0, 0.0), (dx, H + 4.0 * dx, dx), dx, boundary="slip", boundary_faces="xz"),
        time=TimeControl(end=end, frame_interval=end / n_frames, cfl=cfl, dt=dt or 0.0, gravity=(0.0, -G, 0.0),
                         gravity_ramp=ramp, damping=damping, damping_until=2.0 * end),
        materials={"weak_layer": wl, "slab": slab},
        blocks=(Block("weak_layer", (0.0, 0.0, 0.0), (dx, D_wl, dx), particles_per_cell=ppc, name="weak_layer"),
                Block("slab", (0.0, D_wl, 0.0), (dx, H, dx), particles_per_cell=ppc, name="slab")),
        walls=(Wall((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), kind="sticky", name="floor"),),
        output=Output(fields=("x", "log_jp", "p", "q")),
        precision=precision,
    )
    info = {"W_slab": W_slab, "omega_start": omega_start, "omega_end": omega_end, "damping": damping, "end": end,
            "ramp": ramp, "collapse_theory": c_end, "D_wl": D_wl, "h_slab": h_slab, "rho_slab": rho_slab,
            "rho_wl": rho_wl, "dx": dx}
    return sc, wl, info


def measure_column(sim: Simulation, wl: CamClaySnow, info: dict) -> dict:
    """Weak-layer measurements of a settled :func:`weak_layer_column` run.

    Per weak-layer particle: collapse ``c = 1 - exp(log_Jp - log_Jp(0))``, Kirchhoff
    ``p, q`` (Pa) and vertical stress, Cauchy ``sigma_v = tau_v / (J_E J_P)``, the
    overburden ``W`` (Pa) at its reference height, ``p0`` from ``log_Jp`` and from the
    ellipse through ``(p, q)``. Returns means and the per-particle arrays (``per_particle``).
    """
    g = next(gr for gr in sim.model.groups if gr.name == "weak_layer")
    sl = slice(g.start, g.end)
    ljp = sim.particle_field("log_jp")[sl].astype(np.float64)
    F = sim.state.elastic_deformation_gradient()[sl]
    tau = kirchhoff_stress(F, wl.mu, wl.lam)
    p, q = pressure_and_mises(tau)
    tau_v = -tau[:, 1, 1]
    dl = ljp - wl.initial_log_jp
    J = np.linalg.det(F) * np.exp(dl)
    y0 = sim.x0[sl, 1]
    W = info["W_slab"] + info["rho_wl"] * G * (info["D_wl"] - y0)
    K = wl.bulk
    p0_hard = K * np.sinh(wl.xi * np.maximum(-ljp, 0.0))
    p0_ell = forms.consolidation_pressure(p, q, wl.M, wl.beta)
    collapse = 1.0 - np.exp(dl)
    # geometric thickness: interface between the top weak-layer and bottom slab particle layers
    x = sim.state.x.numpy().astype(np.float64)
    gs = next(gr for gr in sim.model.groups if gr.name == "slab")
    D_now = 0.5 * (x[sl, 1].max() + x[gs.start:gs.end, 1].min())
    theory = oedometric_collapse(W, wl)
    inner = (y0 > info["dx"]) & (y0 < info["D_wl"] - info["dx"])  # more than a cell from floor and slab
    return {
        "collapse": float(collapse.mean()),
        "collapse_theory": float(theory.mean()),
        "collapse_interior": float(collapse[inner].mean()) if inner.any() else float("nan"),
        "collapse_theory_interior": float(theory[inner].mean()) if inner.any() else float("nan"),
        "collapse_theory_own_state": float(forms.hardening_collapse(p0_ell, K, wl.xi, wl.p0_ini).mean()),
        "h_c": float(collapse.mean() * info["D_wl"]),
        "thickness_change": float(info["D_wl"] - D_now),
        "thickness_change_from_J": float(info["D_wl"] * (1.0 - J.mean())),
        "sigma_v": float((tau_v / J).mean()),
        "W_mean": float(W.mean()),
        "q_over_p": float(q.mean() / p.mean()),
        "p0": float(p0_hard.mean()),
        "p0_over_tau_v": float(p0_hard.mean() / tau_v.mean()),
        "p0_hard_over_ellipse": float(p0_hard.mean() / p0_ell.mean()),
        "per_particle": {"y0": y0, "collapse": collapse, "W": W, "p": p, "q": q, "tau_v": tau_v, "J": J,
                         "p0_hard": p0_hard, "p0_ellipse": p0_ell},
    }


def run_column(settle_tol: float = 1e-3, device: str | None = "cpu", n_threads: int | None = None,
               **kwargs) -> tuple[dict, Simulation, dict]:
    """Build, run and measure a :func:`weak_layer_column` (``kwargs``); return ``(measurements, sim, info)``.

    Stops at the first frame after the ramp where the slab's mean speed ``v``
    leaves less than ``settle_tol`` of the expected collapse height to go
    (``v * 2 / omega_end``, the critically damped time constant). ``info`` gains
    ``t_settled`` (s), ``steps``, ``wall_time`` (s, stepping only), ``n_particles``
    and ``result`` (the :class:`RunResult`).
    """
    sc, wl, info = weak_layer_column(**kwargs)
    sim = Simulation(sc, device=device, n_threads=n_threads)
    gs = next(gr for gr in sim.model.groups if gr.name == "slab")
    h_expected = info["collapse_theory"] * info["D_wl"]

    def settled(s: Simulation, frame: int):
        if s.time < info["ramp"]:
            return None
        v = float(np.abs(s.state.v.numpy()[gs.start:gs.end, 1].astype(np.float64).mean()))
        return not (v * 2.0 / info["omega_end"] < settle_tol * h_expected)

    res = sim.run(None, callback=settled)
    info.update(t_settled=sim.time, steps=res.steps, wall_time=res.wall_time, n_particles=res.n_particles,
                result=res)
    return measure_column(sim, wl, info), sim, info


def weak_layer_collapse(dx: float = 1.0 / 256.0, *, cfl: float = 0.4, dt: float | None = None,
                        precision: str = "float64", device: str | None = None, n_threads: int | None = None,
                        xi: float = 0.04, rho_slab: float = 1200.0, p0_ini: float = 0.0,
                        D_wl: float = 1.0 / 32.0, h_slab: float = 1.0 / 16.0) -> dict:
    """Weak-layer collapse under a slab against the hardening rule (docs/validation.md "Snow"; SI Note 3).

    :func:`weak_layer_column` (Cam-Clay layer E 0.2 MPa, nu 0.3, rho 150, M 1,
    beta 0.3 under an elastic slab E 1 MPa), run until settled by :func:`run_column`.

    Parameters
    ----------
    dx : float
        Grid spacing (m); ``D_wl / dx`` and ``h_slab / dx`` must be whole numbers
        (binary spacings; the tests use 1/256: 8 cells across the layer).
    cfl, dt, precision, device, n_threads
        As :func:`axial_bar`. float64 by default, as ``benchmarks/convergence/mesh_study.py``.
    xi : float
        Hardening factor (-).
    rho_slab : float
        Slab density (kg/m^3): sets the load ``W = rho_slab g h_slab`` (Pa).
    p0_ini : float
        Initial consolidation pressure of the layer (Pa).
    D_wl, h_slab : float
        Weak-layer and slab thickness (m).

    Returns
    -------
    dict
        The record of the module docstring; ``error = |mean(1 - J_P) / closed form - 1|``
        over the whole layer, the closed form :func:`oedometric_collapse` evaluated at
        each particle's overburden and averaged (``measured``, ``reference``: mean
        ``1 - J_P``, dimensionless). ``details``: collapse height ``h_c`` (m), the
        error of the interior (more than a cell from floor and slab), mean Cauchy
        ``sigma_v`` and overburden (Pa), settling time (s).
    """
    _cells("D_wl", D_wl, dx)
    _cells("h_slab", h_slab, dx)
    m, sim, info = run_column(dx=dx, xi=xi, rho_slab=rho_slab, p0_ini=p0_ini, D_wl=D_wl, h_slab=h_slab, cfl=cfl,
                              dt=dt, precision=precision, device=device, n_threads=n_threads)
    ci, cti = m["collapse_interior"], m["collapse_theory_interior"]
    details = {"cells_across_layer": round(D_wl / dx), "h_c_m": m["h_c"], "h_c_theory_m": m["collapse_theory"] * D_wl,
               "interior_error": ci / cti - 1.0 if math.isfinite(ci) else None, "sigma_v_pa": m["sigma_v"],
               "overburden_pa": m["W_mean"], "t_settled_s": info["t_settled"], "xi": xi, "rho_slab": rho_slab,
               "p0_ini": p0_ini}
    return _record("weak_layer_collapse", sim, info["result"], dx, cfl, dt, m["collapse"], m["collapse_theory"],
                   m["collapse"] / m["collapse_theory"] - 1.0, details)
