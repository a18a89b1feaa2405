"""Vector and matrix types for a given scalar type."""

import functools

import warp as wp


@functools.cache
def vec3(T):
    """3-vector of scalar type ``T``."""
    return wp.types.vector(3, T)


@functools.cache
def mat33(T):
    """3x3 matrix of scalar type ``T``."""
    return wp.types.matrix((3, 3), T)
