"""The 2D P2G's scatter as 4-lane vector operations on the CPU (a native snippet; plain code on CUDA).

The particle adds ``w_ac m`` to the mass and ``w_ac (m v + (c_x,a + c_y,c))`` to the momentum of stencil
node ``(a, c)``, with ``c_x,a = A[:, 0] (a - f_x) dx`` and ``c_y,c = A[:, 1] (c - f_y) dx`` (``A`` the
MLS-MPM affine matrix; ``kernels/p2g.py``). The momenta of a row's nodes ``c = 0, 1`` are four adjacent
numbers, added as one 4-vector; node 2's as a 2-vector. Warp's CPU code holds a 2-vector's lanes as
scalars (and re-scalarizes a Warp 4-vector), with the compiler's vector types the scatter takes fewer
instructions. Every product and sum is the Warp form's, in the same order, one per statement; the CPU
code lets the compiler fuse a product and the sum it feeds into one multiply-add (``#pragma clang fp
contract(fast)``, local to the scatter: the rest of P2G, the constitutive update, keeps the default
contraction), one rounding instead of two: the grid agrees with the Warp form to that rounding, and P2G
is 4-8 % faster (16k-262k particles of the elastic block). On CUDA the snippet adds node by node with
atomics, as Warp's ``+=`` does there.
"""

import functools

import warp as wp

from .types import mat, vec, weights

__all__ = ["scatter_rows_func"]


@functools.cache
def scatter_rows_func(T, portable=False):
    """Build ``scatter_rows(grid_m, grid_p, n0, s0, W, fx, dx, mass, mv, A)`` for scalar type ``T``.

    ``grid_m`` (kg/m) and ``grid_p`` (kg/s: momentum per unit depth, ``vec2``) are one flat grid copy,
    ``n0`` the flat index of the base node and ``s0`` the stride of a row along x; ``W`` (3 x 2) and ``fx``
    the stencil weights and offset (``kernels/shape.py``), ``dx`` (m), ``mass`` (kg/m), ``mv`` (kg/s) and
    ``A`` (kg/s: ``m C - dt V0 4/dx^2 tau``). ``portable`` builds CUDA's node-by-node code on the CPU too
    (``tests/test_native_rows.py`` compares the two there).
    """
    V = vec(2, T)
    M = mat(2, T)
    Wt = weights(2, T)
    s = "float" if T == wp.float32 else "double"
    snippet = f"""
    {s} wy[3] = {{W.data[0][1], W.data[1][1], W.data[2][1]}};
    {s} ey0 = (({s})0 - fx.c[1]) * dx;
    {s} ey1 = (({s})1 - fx.c[1]) * dx;
    {s} ey2 = (({s})2 - fx.c[1]) * dx;
    {s} cy[6] = {{A.data[0][1] * ey0, A.data[1][1] * ey0, A.data[0][1] * ey1, A.data[1][1] * ey1,
                 A.data[0][1] * ey2, A.data[1][1] * ey2}};
    {s} m0 = mv.c[0], m1 = mv.c[1];
#if defined(__CUDA_ARCH__) || {int(portable)}
    for (int a = 0; a < 3; ++a) {{
        int na = n0 + a * s0;
        {s} wa = W.data[a][0];
        {s} ex = (({s})a - fx.c[0]) * dx;
        {s} cx0 = A.data[0][0] * ex;
        {s} cx1 = A.data[1][0] * ex;
        for (int c = 0; c < 3; ++c) {{
            {s} w = wa * wy[c];
            {s} wm = w * mass;
            wp::atomic_add(grid_m.data + (na + c), wm);
            {s} q0 = cx0 + cy[2 * c];
            {s} q1 = cx1 + cy[2 * c + 1];
            q0 = m0 + q0;
            q1 = m1 + q1;
            wp::vec_t<2, {s}> p;
            p.c[0] = w * q0;
            p.c[1] = w * q1;
            wp::atomic_add(grid_p.data + (na + c), p);
        }}
    }}
#else
    {{
#pragma clang fp contract(fast)
    typedef {s} v4 __attribute__((ext_vector_type(4)));
    typedef {s} v2 __attribute__((ext_vector_type(2)));
    {s}* gm = ({s}*)grid_m.data;
    {s}* gp = ({s}*)grid_p.data;
    v4 cy01 = {{cy[0], cy[1], cy[2], cy[3]}};
    v2 cy2 = {{cy[4], cy[5]}};
    v4 mv4 = {{m0, m1, m0, m1}};
    v2 mv2 = {{m0, m1}};
    for (int a = 0; a < 3; ++a) {{
        int na = n0 + a * s0;
        {s} wa = W.data[a][0];
        {s} ex = (({s})a - fx.c[0]) * dx;
        {s} cx0 = A.data[0][0] * ex;
        {s} cx1 = A.data[1][0] * ex;
        {s} w0 = wa * wy[0];
        {s} w1 = wa * wy[1];
        {s} w2 = wa * wy[2];
        {s} wm0 = w0 * mass;
        {s} wm1 = w1 * mass;
        {s} wm2 = w2 * mass;
        gm[na] += wm0;
        gm[na + 1] += wm1;
        gm[na + 2] += wm2;
        v4 cx4 = {{cx0, cx1, cx0, cx1}};
        v2 cx2 = {{cx0, cx1}};
        v4 q01 = cx4 + cy01;
        q01 = mv4 + q01;
        v4 w01 = {{w0, w0, w1, w1}};
        v4 p01 = w01 * q01;
        v4 g01;
        __builtin_memcpy(&g01, gp + 2 * na, sizeof(g01));
        g01 = g01 + p01;
        __builtin_memcpy(gp + 2 * na, &g01, sizeof(g01));
        v2 q2 = cx2 + cy2;
        q2 = mv2 + q2;
        v2 p2 = w2 * q2;
        v2 g2;
        __builtin_memcpy(&g2, gp + 2 * (na + 2), sizeof(g2));
        g2 = g2 + p2;
        __builtin_memcpy(gp + 2 * (na + 2), &g2, sizeof(g2));
    }}
    }}
#endif
"""

    @wp.func_native(snippet)
    def scatter_rows(grid_m: wp.array(dtype=T), grid_p: wp.array(dtype=V), n0: int, s0: int, W: Wt, fx: V, dx: T,
                     mass: T, mv: V, A: M):
        ...

    return scatter_rows
