"""The lecture's Hermite bicubic patch, converted exactly to a cubic Bézier patch.

``S(s, t) = [s^3 s^2 s 1] M B M^T [t^3 t^2 t 1]^T`` with the Hermite matrix ``M`` and the
geometry matrix ``B`` of corners, s- and t-tangents and twists.  Since the Hermite and
Bernstein cubics span the same space, ``B`` maps to Bézier control points by
``C = A B A^T`` with ``A`` below (``c1 = p0 + d0/3``, ``c2 = p1 - d1/3``).
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..errors import SurfmodError
from .bezier import BezierSurface

#: Maps the Hermite data (p0, p1, d0, d1) of a cubic to its Bézier control points.
HERMITE_TO_BEZIER = np.array(
    [[1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 1.0 / 3.0, 0.0], [0.0, 1.0, 0.0, -1.0 / 3.0], [0.0, 1.0, 0.0, 0.0]]
)


def geometry_matrix(corners, du, dv, twist) -> np.ndarray:
    """The lecture's 4x4 (x3) geometry matrix ``B``, rows/cols ordered (P0, P1, P'0, P'1)."""
    b = np.empty((4, 4, 3))
    b[:2, :2] = corners
    b[:2, 2:] = dv
    b[2:, :2] = du
    b[2:, 2:] = twist
    return b


class HermiteBicubic(BezierSurface):
    """Hermite bicubic patch on ``[0, 1]^2``; each argument is ``(2, 2, 3)`` indexed
    ``[i_s, i_t]``: ``corners[i, j] = S(i, j)``, ``du = dS/ds``, ``dv = dS/dt``,
    ``twist = d2S/dsdt`` at the corner ``(i, j)``.

    >>> import numpy as np, surfmod as sm
    >>> c = np.zeros((2, 2, 3)); c[1, :, 0] = 1; c[:, 1, 1] = 1
    >>> du = np.zeros((2, 2, 3)); du[..., 0] = 1
    >>> dv = np.zeros((2, 2, 3)); dv[..., 1] = 1
    >>> sm.HermiteBicubic(c, du, dv, np.zeros((2, 2, 3))).points(0.5, 0.5)
    array([0.5, 0.5, 0. ])
    """

    occt_construct = "Geom_BezierSurface (exact Hermite conversion)"

    def __init__(self, corners, du, dv, twist):
        arrays = []
        for name, value in (("corners", corners), ("du", du), ("dv", dv), ("twist", twist)):
            arr = checks.finite_array(value, name)
            if arr.shape != (2, 2, 3):
                raise SurfmodError(f"{name}: expected shape (2, 2, 3) indexed [i_s, i_t], got {arr.shape}")
            arrays.append(arr)
        self._set_hermite(*arrays)

    def _set_hermite(self, corners, du, dv, twist):
        self.corners, self.du, self.dv, self.twist = (checks.frozen(a) for a in (corners, du, dv, twist))
        b = geometry_matrix(corners, du, dv, twist)
        net = np.einsum("ia,abk,jb->ijk", HERMITE_TO_BEZIER, b, HERMITE_TO_BEZIER)
        self._set_bezier(net, None)

    def transformed(self, matrix) -> "HermiteBicubic":
        """Corners map affinely, tangents and twists linearly: still a Hermite patch."""
        m = transforms.affine(matrix)
        obj = HermiteBicubic._construct_fast()
        obj._set_hermite(
            transforms.apply(m, self.corners),
            transforms.apply_vectors(m, self.du),
            transforms.apply_vectors(m, self.dv),
            transforms.apply_vectors(m, self.twist),
        )
        return obj
