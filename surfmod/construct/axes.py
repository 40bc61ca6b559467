"""Right-handed frames as OCCT builds them (``gp_Ax2``/``gp_Ax3``) and the derivatives of
sine and cosine: the small pieces every analytic curve and surface of ``construct`` shares."""

from __future__ import annotations

import math

import numpy as np

from .. import checks, transforms
from ..errors import SurfmodError


def default_x_dir(normal) -> np.ndarray:
    """The X direction OCCT's ``gp_Ax2(P, N)`` chooses for the main direction ``N``.

    >>> default_x_dir((0, 0, 1))
    array([1., 0., 0.])
    """
    a, b, c = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    aa, ab, ac = abs(a), abs(b), abs(c)
    if ab <= aa and ab <= ac:
        d = (-c, 0.0, a) if aa > ac else (c, 0.0, -a)
    elif aa <= ab and aa <= ac:
        d = (0.0, -c, b) if ab > ac else (0.0, c, -b)
    else:
        d = (-b, a, 0.0) if aa > ab else (b, -a, 0.0)
    d = np.array(d, dtype=float) + 0.0
    return d / np.linalg.norm(d)


def make_frame(origin, axis, x_dir=None, *, origin_name="center", axis_name="axis", x_name="x_dir"):
    """A direct orthonormal frame ``(o, x, y, z)`` from an origin, a main direction and an
    optional X direction (default: OCCT's ``gp_Ax2`` rule); ``x_dir`` must not be parallel
    to the axis (its component along the axis is removed).

    >>> o, x, y, z = make_frame((1, 2, 3), (0, 0, 2), (1, 0, 1))
    >>> x, y, z
    (array([1., 0., 0.]), array([0., 1., 0.]), array([0., 0., 1.]))
    """
    o = checks.point(origin, origin_name)
    z = checks.direction(axis, axis_name)
    if x_dir is None:
        x = default_x_dir(z)
    else:
        x = checks.direction(x_dir, x_name)
        x = x - np.dot(x, z) * z
        if np.linalg.norm(x) < 1e-9:
            raise SurfmodError(f"{x_name}: parallel to {axis_name}, cannot define the X direction")
        x /= np.linalg.norm(x)
    return o, x, np.cross(z, x), z


def frame_transformed(frame, matrix):
    """``(frame', s)``: the frame moved by a similarity matrix and its scale ``|s|``.

    >>> frame = make_frame((0, 0, 0), (0, 0, 1))
    >>> (o, x, y, z), s = frame_transformed(frame, np.diag([2.0, 2.0, 2.0, 1.0]))
    >>> round(s, 12), z
    (2.0, array([0., 0., 1.]))
    """
    o, x, y, z = frame
    lin = matrix[:3, :3]
    s = float(abs(np.linalg.det(lin)) ** (1.0 / 3.0))
    return (transforms.apply(matrix, o), lin @ x / s, lin @ y / s, lin @ z / s), s


def cos_d(t, k):
    """k-th derivative of cos at t.

    >>> float(cos_d(0.0, 2))
    -1.0
    """
    return np.cos(t + k * math.pi / 2.0)


def sin_d(t, k):
    """k-th derivative of sin at t.

    >>> float(sin_d(0.0, 1))
    1.0
    """
    return np.sin(t + k * math.pi / 2.0)
