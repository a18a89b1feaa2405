"""Kernel and transfer identities (docs/validation.md, exact)."""

import numpy as np
import pytest
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE
from helpers_validation import apic_momenta

import mpm_warp
from mpm_warp.kernels.shape import stencil_func
from mpm_warp.kernels.types import vec3


@pytest.fixture(scope="module", params=["float32", "float64"])
def precision(request):
    return request.param


def _stencil_moments_kernel(T):
    V = vec3(T)
    stencil = stencil_func(T)

    @wp.kernel(enable_backward=False)
    def moments(x: wp.array(dtype=V), origin: V, inv_dx: T, dx: T, out: wp.array2d(dtype=wp.float64)):
        i = wp.tid()
        b, fx, W = stencil(x[i], origin, inv_dx)
        for a in range(3):
            for c in range(3):
                for d in range(3):
                    w = W[a, 0] * W[c, 1] * W[d, 2]
                    r = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                    out[i, 0] += wp.float64(w)
                    for k in range(3):
                        out[i, 1 + k] += wp.float64(w * r[k])
                        for m in range(3):
                            out[i, 4 + 3 * k + m] += wp.float64(w * r[k] * r[m])

    return moments


_KERNELS = {}


@pytest.mark.slow
def test_bspline_partition_of_unity_and_moments(precision):
    """sum w = 1, sum w (x_i - x_p) = 0, sum w (x_i - x_p)(x_i - x_p)^T = dx^2/4 I."""
    T = wp.float64 if precision == "float64" else wp.float32
    if T not in _KERNELS:
        _KERNELS[T] = _stencil_moments_kernel(T)
    rng = np.random.default_rng(0)
    dx = 0.037
    x = rng.uniform(0.1, 1.0, size=(500, 3))
    out = wp.zeros((500, 13), dtype=wp.float64, device=DEVICE)
    wp.launch(_KERNELS[T], 500, inputs=[wp.array(x, dtype=vec3(T), device=DEVICE), vec3(T)(0.0, 0.0, 0.0),
                                         T(1.0 / dx), T(dx), out], device=DEVICE)
    o = out.numpy()
    tol = 1e-5 if precision == "float32" else 1e-12
    np.testing.assert_allclose(o[:, 0], 1.0, atol=tol)
    np.testing.assert_allclose(o[:, 1:4] / dx, 0.0, atol=tol)
    second = o[:, 4:].reshape(-1, 3, 3) / (dx * dx / 4.0)
    np.testing.assert_allclose(second, np.broadcast_to(np.eye(3), second.shape), atol=10 * tol)


def _free_scene(precision, velocity=(0.0, 0.0, 0.0), gravity=(0.0, 0.0, 0.0), dt=1e-4, E=1e4):
    return mpm_warp.Scenario(
        name="free",
        domain=mpm_warp.Domain((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.1, boundary="none"),
        time=mpm_warp.TimeControl(end=10 * dt, frame_interval=10 * dt, dt=dt, gravity=gravity),
        materials={"m": mpm_warp.Elastic(E, 0.25, 100.0)},
        blocks=(mpm_warp.Block("m", (0.3, 0.3, 0.3), (0.7, 0.6, 0.5), velocity=velocity),),
        precision=precision,
    )


def test_affine_field_survives_p2g_g2p(precision):
    """APIC/MLS reproduce v = b + A x: after one step v_p = b + A x_p(old) and C = A."""
    b = np.array([0.3, -0.2, 0.1])
    A = np.array([[0.1, 0.4, -0.2], [-0.3, 0.05, 0.2], [0.25, -0.1, -0.15]])
    sc = _free_scene(precision, velocity=lambda x: b + x @ A.T, dt=1e-7, E=1e-3)
    sim = mpm_warp.Simulation(sc, device=DEVICE)
    sim.state.C.assign(np.broadcast_to(A, (sim.model.n_particles, 3, 3)).copy())
    x_old = sim.state.x.numpy().astype(np.float64)
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(1)
    v = sim.state.v.numpy()
    C = sim.state.C.numpy()
    tol = 2e-5 if precision == "float32" else 1e-10
    np.testing.assert_allclose(v, b + x_old @ A.T, atol=tol)
    np.testing.assert_allclose(C, np.broadcast_to(A, C.shape), atol=20 * tol)


def test_momentum_conserved_without_walls_or_gravity():
    """Linear and angular momentum (with the APIC spin term) conserved to round-off, float64."""
    def vel(x):
        wobble = 0.05 * np.sin(np.array([7.0, 11.0, 13.0]) * x[:, [1, 2, 0]])
        return np.array([0.2, -0.1, 0.05]) + np.cross([0.0, 0.0, 1.5], x - 0.5) + wobble

    sc = _free_scene("float64", velocity=vel, dt=2e-4, E=2e4)
    sim = mpm_warp.Simulation(sc, device=DEVICE)
    P0, L0 = apic_momenta(sim)
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(200)
    P1, L1 = apic_momenta(sim)
    assert sim.energies()["elastic_energy"] > 0.0  # the block is really deforming
    np.testing.assert_allclose(P1, P0, rtol=0, atol=1e-12 * np.abs(P0).max() + 1e-14)
    np.testing.assert_allclose(L1, L0, rtol=0, atol=1e-10 * np.abs(L0).max())


def test_free_fall_exact(precision):
    """v = n g dt exactly, x follows symplectic Euler, and no stress grows."""
    g = np.array([0.0, -9.81, 0.0])
    dt = 1e-3
    sc = _free_scene(precision, gravity=tuple(g), dt=dt)
    sim = mpm_warp.Simulation(sc, device=DEVICE)
    x0 = sim.state.x.numpy().astype(np.float64)
    n = 50
    sim.step_to(n * dt)
    v = sim.state.v.numpy().astype(np.float64)
    x = sim.state.x.numpy().astype(np.float64)
    tol = 1e-5 if precision == "float32" else 1e-12
    np.testing.assert_allclose(v, np.broadcast_to(n * g * dt, v.shape), atol=tol * 10)
    expected = x0 + g * dt * dt * n * (n + 1) / 2.0
    np.testing.assert_allclose(x, expected, atol=tol * 10)
    p, q = sim.stress_invariants()
    # round-off only: C is the rounding error of sum w g (x_i - x_p) for a uniform grid velocity g
    rel = 1e-5 if precision == "float32" else 1e-12
    assert np.abs(p).max() < rel * 1e4 and np.abs(q).max() < rel * 1e4  # Pa, against E = 1e4 Pa


def test_rigid_spin_builds_no_stress():
    """A block spinning rigidly (90 degrees) keeps its stress at round-off level."""
    omega = 2.0  # rad/s
    c = np.array([0.5, 0.45, 0.4])

    def vel(x):
        return np.cross([0.0, 0.0, omega], x - c)

    E = 1e5
    sc = mpm_warp.Scenario(
        name="spin",
        domain=mpm_warp.Domain((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.05, boundary="none"),
        time=mpm_warp.TimeControl(end=1.0, frame_interval=0.1, cfl=0.4, gravity=(0.0, 0.0, 0.0)),
        materials={"m": mpm_warp.Elastic(E, 0.3, 500.0)},
        blocks=(mpm_warp.Block("m", (0.35, 0.3, 0.35), (0.65, 0.6, 0.45), velocity=vel),),
        precision="float32",
    )
    sim = mpm_warp.Simulation(sc, device=DEVICE)
    ke0 = sim.energies()["kinetic_energy"]
    sim.step_to(np.pi / 2 / omega)
    e = sim.energies()
    _, q = sim.stress_invariants()
    assert e["elastic_energy"] < 1e-3 * ke0
    assert q.max() < 1e-3 * E
    assert abs(e["kinetic_energy"] - ke0) < 0.02 * ke0
