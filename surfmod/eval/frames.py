"""Moving frames along a space curve, vectorized: Frenet and rotation-minimizing.

Frames are rotation matrices ``R`` of shape ``(N, 3, 3)`` whose columns are ``(T, N, B)``:
tangent, normal, binormal.  The rotation-minimizing frame is tabulated once at construction
(double reflection), then reached from the nearest entry.  See :doc:`/guide/surfaces`
(section "Swept surfaces").
"""

from __future__ import annotations

import numpy as np


def frenet_frames(d1: np.ndarray, d2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frenet frames ``(N, 3, 3)`` from first and second derivatives ``(N, 3)``, plus the
    curvature ``(N,)`` (frames are NaN where the curvature is zero).

    >>> import numpy as np
    >>> R, k = frenet_frames(np.array([[0.0, 2.0, 0.0]]), np.array([[-2.0, 0.0, 0.0]]))
    >>> (R[0].round(12) + 0.0).tolist(), float(k[0])
    ([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], 0.5)
    """
    speed = np.linalg.norm(d1, axis=-1)
    t = d1 / speed[:, None]
    b = np.cross(d1, d2)
    bn = np.linalg.norm(b, axis=-1)
    kappa = bn / speed**3
    with np.errstate(invalid="ignore", divide="ignore"):
        b = b / bn[:, None]
    n = np.cross(b, t)
    return np.stack([t, n, b], axis=-1), kappa


def double_reflection(x0, t0, r0, x1, t1) -> np.ndarray:
    """Transport normals ``r0`` at points ``x0`` with unit tangents ``t0`` to points ``x1``
    with tangents ``t1`` (all ``(N, 3)``), by two reflections; returns ``r1`` ``(N, 3)``."""
    v1 = x1 - x0
    c1 = np.sum(v1 * v1, axis=-1, keepdims=True)
    safe1 = np.where(c1 > 0, c1, 1.0)
    rl = r0 - np.where(c1 > 0, 2.0 / safe1 * np.sum(v1 * r0, axis=-1, keepdims=True), 0.0) * v1
    tl = t0 - np.where(c1 > 0, 2.0 / safe1 * np.sum(v1 * t0, axis=-1, keepdims=True), 0.0) * v1
    v2 = t1 - tl
    c2 = np.sum(v2 * v2, axis=-1, keepdims=True)
    safe2 = np.where(c2 > 0, c2, 1.0)
    r1 = rl - np.where(c2 > 0, 2.0 / safe2 * np.sum(v2 * rl, axis=-1, keepdims=True), 0.0) * v2
    # re-orthonormalize against round-off
    r1 = r1 - np.sum(r1 * t1, axis=-1, keepdims=True) * t1
    return r1 / np.linalg.norm(r1, axis=-1, keepdims=True)


def any_normal(t: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to the unit vector ``t`` (3,)."""
    axis = np.eye(3)[int(np.argmin(np.abs(t)))]
    n = axis - (axis @ t) * t
    return n / np.linalg.norm(n)


class RotationMinimizingTable:
    """Rotation-minimizing normals on a table of curve samples, and their vectorized
    transport to any parameter.

    ``params`` (K,), ``points`` and unit ``tangents`` (K, 3) describe the table;
    ``normal0`` is the start normal (perpendicular to ``tangents[0]``).
    """

    def __init__(self, params, points, tangents, normal0):
        self.params = np.asarray(params, dtype=float)
        self.points = np.asarray(points, dtype=float)
        self.tangents = np.asarray(tangents, dtype=float)
        k = self.params.size
        normals = np.empty((k, 3))
        r = np.asarray(normal0, dtype=float)
        r = r - (r @ self.tangents[0]) * self.tangents[0]
        normals[0] = r / np.linalg.norm(r)
        for i in range(k - 1):  # sequential by nature: one step per table entry
            normals[i + 1] = double_reflection(
                self.points[i : i + 1], self.tangents[i : i + 1], normals[i : i + 1],
                self.points[i + 1 : i + 2], self.tangents[i + 1 : i + 2],
            )[0]
        self.normals = normals

    def frames(self, t: np.ndarray, points: np.ndarray, tangents: np.ndarray) -> np.ndarray:
        """Frames ``(N, 3, 3)`` (columns T, N, B) at parameters ``t`` whose curve points
        and unit tangents are given."""
        i = np.clip(np.searchsorted(self.params, t, side="right") - 1, 0, self.params.size - 1)
        r = double_reflection(self.points[i], self.tangents[i], self.normals[i], points, tangents)
        b = np.cross(tangents, r)
        return np.stack([tangents, r, b], axis=-1)


def axis_rotation(angles: np.ndarray) -> np.ndarray:
    """Rotations ``(N, 3, 3)`` about the first axis by ``angles`` (radians), used to twist
    a frame about its tangent: ``R @ axis_rotation(a)``."""
    c, s = np.cos(angles), np.sin(angles)
    out = np.zeros(np.shape(angles) + (3, 3))
    out[..., 0, 0] = 1.0
    out[..., 1, 1], out[..., 1, 2] = c, -s
    out[..., 2, 1], out[..., 2, 2] = s, c
    return out
