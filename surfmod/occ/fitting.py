"""OCCT's own surface fitting (``GeomAPI_PointsToBSplineSurface``), for comparisons.

The same concept as :mod:`surfmod.construct.fitting`, of which this is the OCCT twin.
"""

from __future__ import annotations

import numpy as np
from OCP.Approx import Approx_ParametrizationType
from OCP.GeomAbs import GeomAbs_Shape
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface

from ..errors import KernelError
from . import arrays
from .guard import kernel


def points_to_bspline_surface(points: np.ndarray, degree=(3, 3), tolerance: float = 1e-6, *, interpolate: bool):
    """OCCT's B-spline through (``interpolate``) or near an ``(n, m, 3)`` grid.

    Interpolation is OCCT's bicubic C2 ``Interpolate`` with chord-length parameters;
    approximation is ``Init`` with degrees ``max(degree)``..8, C2 and ``tolerance``.
    """
    pts = arrays.points_2d(np.asarray(points, dtype=float))
    with kernel("GeomAPI_PointsToBSplineSurface"):
        fit = GeomAPI_PointsToBSplineSurface()
        if interpolate:
            fit.Interpolate(pts, Approx_ParametrizationType.Approx_ChordLength, False)
        else:
            deg = max(int(degree[0]), int(degree[1]))
            fit.Init(pts, Approx_ParametrizationType.Approx_ChordLength, deg, max(deg, 8),
                     GeomAbs_Shape.GeomAbs_C2, float(tolerance), False)
        if not fit.IsDone():
            raise KernelError("GeomAPI_PointsToBSplineSurface: fit failed")
        return fit.Surface()
