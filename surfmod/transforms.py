"""4x4 affine matrices for the named transforms and their application to point arrays."""

from __future__ import annotations

import numpy as np

from . import checks
from .errors import SurfmodError


def affine(matrix) -> np.ndarray:
    """Validate a 4x4 affine matrix (last row ``0 0 0 1``, invertible linear part)."""
    m = checks.finite_array(matrix, "matrix")
    if m.shape != (4, 4):
        raise SurfmodError(f"matrix: expected a 4x4 affine matrix, got shape {m.shape}")
    if not np.allclose(m[3], (0.0, 0.0, 0.0, 1.0), atol=1e-14):
        raise SurfmodError("matrix: last row must be (0, 0, 0, 1) for an affine map")
    if abs(np.linalg.det(m[:3, :3])) < 1e-14:
        raise SurfmodError("matrix: linear part is singular")
    return m


def apply(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply an affine matrix to ``(..., 3)`` points."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def apply_vectors(matrix: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """Apply the linear part only (directions, derivatives)."""
    return vectors @ matrix[:3, :3].T


def is_similarity(matrix: np.ndarray) -> bool:
    """True for rotations/mirrors times a uniform scale (OCCT's ``gp_Trsf`` kinds)."""
    lin = matrix[:3, :3]
    gram = lin.T @ lin
    return bool(np.allclose(gram, gram[0, 0] * np.eye(3), rtol=1e-12, atol=1e-12 * gram[0, 0]))


def translation_matrix(vector) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = checks.point(vector, "vector")
    return m


def rotation_matrix(axis_origin, axis_direction, degrees) -> np.ndarray:
    """Rodrigues rotation about an axis through ``axis_origin``."""
    o = checks.point(axis_origin, "axis_origin")
    k = checks.direction(axis_direction, "axis_direction")
    angle = np.radians(checks.angle(degrees, "degrees"))
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    rot = np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * (kx @ kx)
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = o - rot @ o
    return m


def mirror_matrix(point, normal) -> np.ndarray:
    """Householder reflection in the plane through ``point``."""
    p = checks.point(point, "point")
    n = checks.direction(normal, "normal")
    ref = np.eye(3) - 2.0 * np.outer(n, n)
    m = np.eye(4)
    m[:3, :3] = ref
    m[:3, 3] = p - ref @ p
    return m


def scale_matrix(factor, center=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Uniform (a number) or non-uniform (three numbers) scale about ``center``."""
    f = checks.finite_array(factor, "factor")
    f = np.full(3, f.item()) if f.size == 1 else f
    if f.shape != (3,):
        raise SurfmodError(f"factor: expected a number or 3 numbers, got shape {f.shape}")
    if np.any(f == 0.0):
        raise SurfmodError("factor: scale factors must be non-zero")
    c = checks.point(center, "center")
    m = np.eye(4)
    m[:3, :3] = np.diag(f)
    m[:3, 3] = c - f * c
    return m


class Transformable:
    """The named transforms of a surface or curve, each a matrix given to the object's
    own ``transformed(matrix)``."""

    __slots__ = ()

    def translated(self, vector):
        """A copy moved by ``vector``."""
        return self.transformed(translation_matrix(vector))

    def rotated(self, axis_origin, axis_direction, degrees: float):
        """A copy rotated by ``degrees`` about the axis (right-hand rule)."""
        return self.transformed(rotation_matrix(axis_origin, axis_direction, degrees))

    def mirrored(self, point, normal):
        """A copy mirrored in the plane through ``point`` with ``normal``."""
        return self.transformed(mirror_matrix(point, normal))

    def scaled(self, factor, center=(0.0, 0.0, 0.0)):
        """A copy scaled about ``center``; ``factor`` is a number or three (non-uniform)."""
        return self.transformed(scale_matrix(factor, center))
