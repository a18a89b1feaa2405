"""Warp kernels of mpm_warp (installed as ``mpm_warp.kernels``).

This layer imports only ``warp``. Every kernel and device function is built by
a cached factory taking the scalar type ``T`` (``wp.float32`` or
``wp.float64``), so float32 and float64 variants come from one source and no
tunable number lives at module level (dx, dt and material parameters arrive as
kernel arguments, so a new dx never recompiles).

Conventions inside kernels: every literal is wrapped as ``T(...)`` because
Warp does not mix float32 and float64 in arithmetic.
"""
