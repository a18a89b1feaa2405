"""Grid update: nodal momentum to velocity, gravity, walls (MODEL.md 5).

Walls are planes ``(point, normal)`` with the normal pointing into the
material. A node with signed distance ``phi = (x_i - p(t)) . n <= 1e-3 dx``
lies in the wall and its velocity relative to the wall is constrained:

- ``STICKY``: relative velocity set to zero;
- ``SLIP``: normal component removed, tangential kept (frictionless, bonded);
- ``SEPARATE``: only an approaching normal component is removed, and Coulomb
  friction ``mu`` acts on the tangential part (sticks while
  ``|v_t| <= -mu v_n``).

The impulse each wall gives the material is accumulated per wall, so the mean
reaction force over a frame is ``impulse / frame duration``. The wall code is
compiled only into scenes that have walls.
"""

import functools

import warp as wp

from .types import vec

STICKY = 0
SLIP = 1
SEPARATE = 2


@functools.cache
def wall_struct(T, dim=3):
    """Kernel-side wall description for scalar type ``T`` and dimension ``dim``.

    Fields: ``point`` (m) at t = 0, ``normal`` (unit, into the material),
    ``velocity`` (m/s) reached after ``ramp_time`` (s, linear ramp from rest;
    0 means constant from the start), ``kind`` (0 sticky, 1 slip, 2 separate),
    ``friction`` (Coulomb coefficient, -).
    """
    V = vec(dim, T)

    @wp.struct
    class WallParams:
        point: V
        normal: V
        velocity: V
        ramp_time: T
        kind: wp.int32
        friction: T

    return WallParams


@functools.cache
def wall_motion_func(T, dim=3):
    """Return ``motion(wall, t) -> (point(t), velocity(t))`` evaluated on the device."""
    WallParams = wall_struct(T, dim)

    @wp.func
    def motion(w: WallParams, t: T):
        vel = w.velocity
        disp = w.velocity * t
        if w.ramp_time > T(0.0):
            if t < w.ramp_time:
                vel = w.velocity * (t / w.ramp_time)
                disp = w.velocity * (T(0.5) * t * t / w.ramp_time)
            else:
                disp = w.velocity * (t - T(0.5) * w.ramp_time)
        return w.point + disp, vel

    return motion


@functools.cache
def grid_update_kernel(dim, T, has_walls: bool):
    """Build the grid update kernel (launched over all nodes, or a slab of them) for dimension ``dim``.

    ``grid_m`` / ``grid_p`` have a leading axis of grid copies: on the CPU each
    thread scatters into its own copy and this kernel sums them (one copy on
    CUDA). ``grid_p[0]`` holds the summed nodal momentum (kg m/s) on entry
    and the velocity (m/s) on exit. The launch covers nodes ``i0 + tid``
    along x. ``vmax[0]`` receives the largest nodal speed (m/s), used by the
    automatic time step of the next step. Wall impulses (N s; N s/m in plane
    strain) are summed in float64: up to a million atomic adds per frame.
    """
    V = vec(dim, T)
    VD = vec(dim, wp.float64)
    Vi = wp.types.vector(dim, wp.int32)
    WallParams = wall_struct(T, dim)
    motion = wall_motion_func(T, dim)

    @wp.func
    def node_sum(grid_m: wp.array(dtype=T, ndim=dim + 1), grid_p: wp.array(dtype=V, ndim=dim + 1), n: Vi):
        """Mass and momentum of node ``n`` summed over the grid copies."""
        m = T(0.0)
        mom = V()
        for c in range(grid_m.shape[0]):
            if wp.static(dim == 2):
                m += grid_m[c, n[0], n[1]]
                mom += grid_p[c, n[0], n[1]]
            else:
                m += grid_m[c, n[0], n[1], n[2]]
                mom += grid_p[c, n[0], n[1], n[2]]
        return m, mom

    @wp.func
    def node_store(grid_p: wp.array(dtype=V, ndim=dim + 1), n: Vi, vel: V):
        if wp.static(dim == 2):
            grid_p[0, n[0], n[1]] = vel
        else:
            grid_p[0, n[0], n[1], n[2]] = vel

    @wp.kernel(enable_backward=False, module="unique")
    def grid_update(
        grid_m: wp.array(dtype=T, ndim=dim + 1),
        grid_p: wp.array(dtype=V, ndim=dim + 1),
        i0: int,
        dt_arr: wp.array(dtype=T),
        clock: wp.array(dtype=wp.float64),
        gravity: V,
        gravity_ramp: T,
        damping: T,
        damping_until: T,
        mass_threshold: T,
        origin: V,
        dx: T,
        walls: wp.array(dtype=WallParams),
        wall_impulse: wp.array(dtype=VD),
        vmax: wp.array(dtype=T),
    ):
        n = Vi()
        if wp.static(dim == 2):
            ii, j = wp.tid()
            n = Vi(ii + i0, j)
        else:
            ii, j, k = wp.tid()
            n = Vi(ii + i0, j, k)
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        m, mom = node_sum(grid_m, grid_p, n)
        if m <= mass_threshold:
            node_store(grid_p, n, V())
            return
        t = T(clock[0])
        g_scale = T(1.0)
        if gravity_ramp > T(0.0):
            g_scale = wp.min(t / gravity_ramp, T(1.0))
        vel = mom / m + (dt * g_scale) * gravity
        if t < damping_until:
            vel = vel * wp.max(T(1.0) - damping * dt, T(0.0))
        if wp.static(has_walls):
            xn = V()
            for a in range(dim):
                xn[a] = origin[a] + T(n[a]) * dx
            for w in range(walls.shape[0]):
                wall = walls[w]
                pw, vw = motion(wall, t + dt)
                nrm = wall.normal
                # nodes on the plane belong to the wall; the 1e-3 dx margin absorbs the rounding of origin + i dx
                if wp.dot(xn - pw, nrm) <= T(1.0e-3) * dx:
                    v_old = vel
                    vrel = vel - vw
                    vn = wp.dot(vrel, nrm)
                    if wall.kind == 0:
                        vrel = V()
                    elif wall.kind == 1:
                        vrel = vrel - vn * nrm
                    elif vn < T(0.0):
                        vt = vrel - vn * nrm
                        vt_norm = wp.length(vt)
                        if vt_norm <= -wall.friction * vn:
                            vrel = V()
                        else:
                            vrel = vt * (T(1.0) + wall.friction * vn / vt_norm)
                    vel = vw + vrel
                    wp.atomic_add(wall_impulse, w, VD(m * (v_old - vel)))
        node_store(grid_p, n, vel)
        wp.atomic_max(vmax, 0, wp.length(vel))

    return grid_update
