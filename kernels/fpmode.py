"""Subnormal numbers flushed to zero on the threads of the CPU step (x86-64: MXCSR's FTZ and DAZ bits).

A particle at rest or in free fall has a displacement gradient ``H`` and a velocity gradient ``C`` of
round-off size (1e-35 to 1e-9 in float32): the trial's ``L H`` (``kernels/constitutive.py``) then multiplies
two such numbers, and the product falls below float32's smallest normal number (1.2e-38). An x86 core
computes a subnormal result, or takes a subnormal input, through a microcode assist of a hundred cycles or
more: the 2D elastic block spent three quarters of its P2G in them (65k particles: 5.9 ms a step, 1.6 ms
with the bits set). With FTZ (results below the normal range are zero) and DAZ (subnormal inputs read as
zero) set, only numbers below 1.2e-38 (float32; 2.2e-308 float64) change, to zero: far below the rounding
of any quantity they are added to (the ``1`` of ``F = I + H`` has a rounding unit of 6e-8).

:func:`flush_kernels` gives two one-thread kernels: ``flush(saved, k)`` keeps the calling thread's control
word in ``saved[k]`` and sets both bits, ``restore(saved, k)`` puts it back. A Warp CPU launch runs on the
calling thread, so the stepper launches ``flush`` on each of its threads before their steps and
``restore`` after them (``mpm_warp/step.py``). Elsewhere (CUDA, a CPU other than x86-64) both are no-ops.
"""

import functools

import warp as wp

__all__ = ["FTZ_DAZ", "flush_kernels"]

#: MXCSR bits: flush to zero (bit 15) and denormals are zero (bit 6)
FTZ_DAZ = 0x8040


@wp.func_native("""
#if defined(__x86_64__) && !defined(__CUDA_ARCH__)
unsigned int old_csr = __builtin_ia32_stmxcsr();
__builtin_ia32_ldmxcsr(old_csr | (unsigned int)bits);
return (int)old_csr;
#else
return 0;
#endif
""")
def _set_csr(bits: int) -> int:
    ...


@wp.func_native("""
#if defined(__x86_64__) && !defined(__CUDA_ARCH__)
__builtin_ia32_ldmxcsr((unsigned int)csr);
#endif
""")
def _load_csr(csr: int):
    ...


@functools.cache
def flush_kernels():
    """Return ``(flush, restore)``: kernels of one thread taking ``(saved: array of int32, k: int)``."""

    @wp.kernel(enable_backward=False, module="unique")
    def flush(saved: wp.array(dtype=wp.int32), k: int):
        saved[k] = _set_csr(FTZ_DAZ)

    @wp.kernel(enable_backward=False, module="unique")
    def restore(saved: wp.array(dtype=wp.int32), k: int):
        _load_csr(saved[k])

    return flush, restore
