"""The 2D G2P's stencil sums as four-lane operations on the CPU (a native snippet; plain code on CUDA).

For a particle with stencil weights ``W`` (3 x 2) and offset ``fx`` from its base node, the 2D G2P needs
per stencil row ``a``: ``r_a = sum_c w_c g_ac`` and ``s_a = sum_c w_c (c - f_y) g_ac`` (``g`` the nodal
velocity), then ``v = sum_a w_a r_a``, ``B_0 = sum_a w_a (a - f_x) r_a`` and ``B_1 = sum_a w_a s_a``
(``kernels/g2p.py``). ``(r_a, s_a)`` is one 4-vector ``sum_c (w_c, w_c, d_c, d_c) (g_ac, g_ac)``, and
``(v, B_1)`` one sum of ``w_a (r_a, s_a)``. Warp's CPU code holds a 2-vector's lanes as scalars; written
with the compiler's vector types the sums take a third of the instructions. The products and sums are
those of the Warp form, in the same order; the compiler's fused multiply-adds (G2P's module options) may
round them differently.
"""

import functools

import warp as wp

from .types import vec, weights

__all__ = ["gather_rows_func"]


@functools.cache
def gather_rows_func(T, portable=False):
    """Build ``gather_rows(grid_v, n0, s0, W, fx) -> mat32``: rows ``v``, ``B_0 / dx``, ``B_1 / dx`` (m/s).

    ``grid_v`` is the flat grid of nodal velocities (``vec2``), ``n0`` the flat index of the base node and
    ``s0`` the stride of a row along x. ``portable`` builds CUDA's plain code on the CPU too
    (``tests/test_native_rows.py`` compares the two there).
    """
    V = vec(2, T)
    Wt = weights(2, T)
    R = wp.types.matrix((3, 2), T)
    s = "float" if T == wp.float32 else "double"
    snippet = f"""
    {s} wy0 = W.data[0][1], wy1 = W.data[1][1], wy2 = W.data[2][1];
    {s} f0 = fx.c[0], f1 = fx.c[1];
    {s} dy0 = wy0 * (({s})0 - f1), dy1 = wy1 * (({s})1 - f1), dy2 = wy2 * (({s})2 - f1);
    wp::mat_t<3, 2, {s}> out;
#if defined(__CUDA_ARCH__) || {int(portable)}
    {s} acc[4] = {{0, 0, 0, 0}}, bx[2] = {{0, 0}};
    for (int a = 0; a < 3; ++a) {{
        const {s}* p = (const {s}*)(grid_v.data + (n0 + a * s0));
        {s} wa = W.data[a][0], ua = wa * (({s})a - f0);
        for (int l = 0; l < 2; ++l) {{
            {s} r = wy0 * p[l] + wy1 * p[2 + l] + wy2 * p[4 + l];
            {s} sy = dy0 * p[l] + dy1 * p[2 + l] + dy2 * p[4 + l];
            acc[l] += wa * r;
            acc[2 + l] += wa * sy;
            bx[l] += ua * r;
        }}
    }}
    out.data[0][0] = acc[0]; out.data[0][1] = acc[1];
    out.data[1][0] = bx[0]; out.data[1][1] = bx[1];
    out.data[2][0] = acc[2]; out.data[2][1] = acc[3];
#else
    typedef {s} v4 __attribute__((ext_vector_type(4)));
    v4 k0 = {{wy0, wy0, dy0, dy0}}, k1 = {{wy1, wy1, dy1, dy1}}, k2 = {{wy2, wy2, dy2, dy2}};
    v4 acc = ({s})0, bx = ({s})0;
    for (int a = 0; a < 3; ++a) {{
        const {s}* p = (const {s}*)(grid_v.data + (n0 + a * s0));
        v4 g0 = {{p[0], p[1], p[0], p[1]}}, g1 = {{p[2], p[3], p[2], p[3]}}, g2 = {{p[4], p[5], p[4], p[5]}};
        v4 t = k0 * g0 + k1 * g1 + k2 * g2;
        {s} wa = W.data[a][0];
        acc += wa * t;
        bx += (wa * (({s})a - f0)) * t;
    }}
    out.data[0][0] = acc.x; out.data[0][1] = acc.y;
    out.data[1][0] = bx.x; out.data[1][1] = bx.y;
    out.data[2][0] = acc.z; out.data[2][1] = acc.w;
#endif
    return out;
"""

    @wp.func_native(snippet)
    def gather_rows(grid_v: wp.array(dtype=V), n0: int, s0: int, W: Wt, fx: V) -> R:
        ...

    return gather_rows
