"""Vector and matrix types for a given dimension and scalar type.

Every kernel factory takes the spatial dimension ``dim`` (2: plane strain, 3)
and the scalar type ``T`` (``wp.float32`` or ``wp.float64``); these helpers give
the matching Warp types, cached so that one factory call always sees the same
type objects.
"""

import functools

import warp as wp


@functools.cache
def vec(dim, T):
    """``dim``-vector of scalar type ``T`` (positions, velocities, grid momenta)."""
    return wp.types.vector(dim, T)


@functools.cache
def mat(dim, T):
    """``dim x dim`` matrix of scalar type ``T`` (affine velocity C, displacement gradient H, stress)."""
    return wp.types.matrix((dim, dim), T)


@functools.cache
def weights(dim, T):
    """``3 x dim`` matrix of quadratic B-spline weights: row ``k`` holds node ``base + k`` per axis."""
    return wp.types.matrix((3, dim), T)


def vec3(T):
    """3-vector of scalar type ``T`` (principal values: singular values, strains, stresses)."""
    return vec(3, T)


def mat33(T):
    """3x3 matrix of scalar type ``T``."""
    return mat(3, T)
