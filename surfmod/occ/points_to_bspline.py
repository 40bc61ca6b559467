"""OCCT's surface fitting, for comparisons: ``GeomAPI_PointsToBSplineSurface`` through or near
a grid, and the fit's independent measure (``Extrema_GenLocateExtPS``).

The OCCT twin of :mod:`surfmod.construct.fitting` and the judge of :mod:`surfmod.ops.fit`.

``project_points`` is the independent measure of a fit: every point is projected onto
the OCCT twin (``Geom_BSplineSurface``) by ``Extrema_GenLocateExtPS`` (distance
criterion, so minima on the border are found), started at the caller's foot-point
parameters; where that local search fails, the global ``GeomAPI_ProjectPointOnSurf``
takes over.  The distance of a point to *any* surface point bounds its distance to the
surface from above, so a maximum measured this way is a guaranteed bound.
"""

from __future__ import annotations

import numpy as np
from OCP.Approx import Approx_ParametrizationType
from OCP.Extrema import Extrema_GenLocateExtPS
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface, GeomAPI_ProjectPointOnSurf
from OCP.GeomAbs import GeomAbs_Shape
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Pnt

from . import arrays
from ..errors import KernelError
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


def project_points(surf, points: np.ndarray, u: np.ndarray, v: np.ndarray):
    """Distances ``(N,)`` and OCCT foot parameters ``(u, v)`` of ``points`` on ``surf``."""
    n = len(points)
    dist = np.empty(n)
    uo, vo = np.empty(n), np.empty(n)
    pts = np.ascontiguousarray(points, dtype=float).tolist()
    us, vs = np.asarray(u, dtype=float).tolist(), np.asarray(v, dtype=float).tolist()
    with kernel("Extrema_GenLocateExtPS"):
        adaptor = GeomAdaptor_Surface(surf)
        local = Extrema_GenLocateExtPS(adaptor, 1e-12, 1e-12)
        glob = None
        p = gp_Pnt()
        for k in range(n):  # the OCCT reference side: one kernel call per point
            x, y, z = pts[k]
            p.SetCoord(x, y, z)
            local.Perform(p, us[k], vs[k], True)
            if local.IsDone():
                dist[k] = local.SquareDistance() ** 0.5
                uo[k], vo[k] = local.Point().Parameter()
                continue
            if glob is None:
                u0, u1, v0, v1 = surf.Bounds()
                glob = GeomAPI_ProjectPointOnSurf()
                glob.Init(surf, u0, u1, v0, v1)
            glob.Perform(p)
            if glob.NbPoints() > 0:
                dist[k] = glob.LowerDistance()
                uo[k], vo[k] = glob.LowerDistanceParameters()
            else:  # no extremum: the surface point at the start bounds the distance
                q = surf.Value(us[k], vs[k])
                dist[k] = q.Distance(p)
                uo[k], vo[k] = us[k], vs[k]
    return dist, uo, vo
