"""Grid update: nodal momentum to velocity, gravity, walls (docs/model.md §5).

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

Layout and cost. The grid is flat (``kernels/p2g.py``: node ``(i, j[, k])`` at
``i s_0 + j s_1 [+ k]``) and a thread updates a segment of one row of nodes
along the last axis (the whole row on the CPU, one node on CUDA), so its node
indices follow without divisions. Work that does not depend on the node is done
once: the gravity increment per thread, the walls' positions and velocities per
step (:func:`wall_state_kernel`), and the speed bound per thread (the largest
squared speed of its nodes, one square root and one atomic max at the end;
``sqrt`` is monotonic and correctly rounded, so this is the largest speed).
The wall tests run only at the ends of a row: the nodes of a row inside a wall
form a prefix or a suffix of it (see the kernel), so a thread tests nodes from
each end until one lies in no wall, and the nodes between skip the wall loop.
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
def wall_state_kernel(T, dim=3):
    """Build the kernel (one thread per wall) that evaluates the walls at the end of the coming step.

    ``state[w] = (point(t + dt), velocity(t + dt))`` of wall ``w`` (m, m/s), with ``t``
    the clock and ``dt`` the step size set by ``begin_step``, in the kernels'
    scalar type: the values every node of the grid update would compute.
    """
    V = vec(dim, T)
    WallParams = wall_struct(T, dim)
    motion = wall_motion_func(T, dim)

    @wp.kernel(enable_backward=False, module="unique")
    def wall_state(walls: wp.array(dtype=WallParams), dt_arr: wp.array(dtype=T), clock: wp.array(dtype=wp.float64),
                   point: wp.array(dtype=V), velocity: wp.array(dtype=V)):
        w = wp.tid()
        pw, vw = motion(walls[w], T(clock[0]) + dt_arr[0])
        point[w] = pw
        velocity[w] = vw

    return wall_state


@functools.cache
def in_wall_func(T, dim=3):
    """Return ``in_wall(x, point, normal, dx) -> bool``: the node at ``x`` (m) lies in the wall through ``point``.

    Nodes on the plane belong to the wall; the ``1e-3 dx`` margin absorbs the rounding of ``origin + i dx``.
    Along a row of nodes (one coordinate of ``x`` moving with the index) the rounded signed distance
    ``(x - point) . normal`` is monotonic in the index (each of its operations is), so the nodes of a row in
    one wall are a prefix, a suffix, all or none of the row.
    """
    V = vec(dim, T)

    @wp.func
    def in_wall(xn: V, point: V, nrm: V, dx: T):
        return wp.dot(xn - point, nrm) <= T(1.0e-3) * dx

    return in_wall


@functools.cache
def grid_update_kernel(dim, T, has_walls: bool):
    """Build the grid update kernel for dimension ``dim``.

    ``grid_m`` / ``grid_p`` hold ``n_copies`` grid copies one after the other
    (flat, ``n_nodes = shape[0] s_0`` nodes each): on the CPU each thread
    scatters into its own copy and this kernel sums them (one copy on CUDA).
    ``grid_p`` copy 0 holds the summed nodal momentum (kg m/s) on entry and
    the velocity (m/s) on exit. A row is a line of nodes along the last axis
    (``(i)`` in 2D, ``(i, j)`` in 3D, numbered ``i shape[1] + j``); thread ``t``
    of a launch updates nodes ``seg_len (t mod n_seg)`` to ``seg_len (t mod n_seg + 1) - 1``
    of row ``row0 + t / n_seg``, ``n_seg = ceil(shape[-1] / seg_len)``. ``vmax[0]``
    receives the largest nodal speed (m/s), used by the automatic time step of
    the next step. ``wall_point`` / ``wall_velocity`` are the walls at the end
    of the step (:func:`wall_state_kernel`). Wall impulses (N s; N s/m in plane
    strain) are summed in float64: up to a million atomic adds per frame.
    """
    V = vec(dim, T)
    VD = vec(dim, wp.float64)
    Vi = wp.types.vector(dim, wp.int32)
    WallParams = wall_struct(T, dim)
    last = dim - 1
    in_wall = in_wall_func(T, dim)

    @wp.func
    def in_any_wall(xn: V, walls: wp.array(dtype=WallParams), wall_point: wp.array(dtype=V), dx: T):
        inside = int(0)
        for w in range(walls.shape[0]):
            if in_wall(xn, wall_point[w], walls[w].normal, dx):
                inside = 1
        return inside != 0

    @wp.kernel(enable_backward=False, module="unique")
    def grid_update(
        grid_m: wp.array(dtype=T),
        grid_p: wp.array(dtype=V),
        n_copies: int,
        row0: int,
        seg_len: int,
        shape: Vi,
        strides: Vi,
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
        wall_point: wp.array(dtype=V),
        wall_velocity: wp.array(dtype=V),
        wall_impulse: wp.array(dtype=VD),
        vmax: wp.array(dtype=T),
    ):
        tid = wp.tid()
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        n_last = shape[last]
        n_seg = (n_last + seg_len - 1) / seg_len
        r = tid
        k0 = 0
        if n_seg > 1:
            r = tid / n_seg
            k0 = (tid - r * n_seg) * seg_len
        k1 = wp.min(k0 + seg_len, n_last)
        row = row0 + r
        xn = V()
        first = 0
        if wp.static(dim == 2):
            first = row * strides[0]
            if wp.static(has_walls):
                xn[0] = origin[0] + T(row) * dx
        else:
            i = row / shape[1]
            j = row - i * shape[1]
            first = i * strides[0] + j * strides[1]
            if wp.static(has_walls):
                xn[0] = origin[0] + T(i) * dx
                xn[1] = origin[1] + T(j) * dx
        n_nodes = shape[0] * strides[0]
        t = T(clock[0])
        g_scale = T(1.0)
        if gravity_ramp > T(0.0):
            g_scale = wp.min(t / gravity_ramp, T(1.0))
        dv_gravity = (dt * g_scale) * gravity
        damped = t < damping_until
        damp = wp.max(T(1.0) - damping * dt, T(0.0))
        v2max = T(0.0)
        # the nodes of the segment inside some wall are a prefix and/or a suffix of it (in_wall_func): between
        # the first and the last node in no wall none is in any wall, and those nodes skip the wall loop
        kl = k0
        kh = k1 - 1
        if wp.static(has_walls):
            while kl <= kh:
                xn[last] = origin[last] + T(kl) * dx
                if not in_any_wall(xn, walls, wall_point, dx):
                    break
                kl += 1
            while kh > kl:
                xn[last] = origin[last] + T(kh) * dx
                if not in_any_wall(xn, walls, wall_point, dx):
                    break
                kh -= 1
        for k in range(k0, k1):
            n = first + k
            m = grid_m[n]
            mom = grid_p[n]
            for c in range(1, n_copies):
                m += grid_m[c * n_nodes + n]
                mom += grid_p[c * n_nodes + n]
            if m <= mass_threshold:
                grid_p[n] = V()
                continue
            vel = mom / m + dv_gravity
            if damped:
                vel = vel * damp
            if wp.static(has_walls):
                if k < kl or k > kh:
                    xn[last] = origin[last] + T(k) * dx
                    for w in range(walls.shape[0]):
                        nrm = walls[w].normal
                        if in_wall(xn, wall_point[w], nrm, dx):
                            kind = walls[w].kind
                            vw = wall_velocity[w]
                            v_old = vel
                            vrel = vel - vw
                            vn = wp.dot(vrel, nrm)
                            if kind == 0:
                                vrel = V()
                            elif kind == 1:
                                vrel = vrel - vn * nrm
                            elif vn < T(0.0):
                                mu = walls[w].friction
                                vt = vrel - vn * nrm
                                vt_norm = wp.length(vt)
                                if vt_norm <= -mu * vn:
                                    vrel = V()
                                else:
                                    vrel = vt * (T(1.0) + mu * vn / vt_norm)
                            vel = vw + vrel
                            wp.atomic_add(wall_impulse, w, VD(m * (v_old - vel)))
            grid_p[n] = vel
            v2max = wp.max(v2max, wp.dot(vel, vel))
        wp.atomic_max(vmax, 0, wp.sqrt(v2max))

    return grid_update
