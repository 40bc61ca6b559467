"""``GeomAPI`` intersections (surface-surface, line-surface) and projections of points onto
surfaces and faces: the kernel twins of :mod:`surfmod.ops.intersect` and
:mod:`surfmod.ops.project`, checked against.  Plain per-item OCCT calls (reference side,
not an evaluation path)."""

from __future__ import annotations

import numpy as np
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.Geom import Geom_Line
from OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.GeomAPI import GeomAPI_IntCS, GeomAPI_IntSS, GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Dir, gp_Lin

from surfmod.occ import arrays
from surfmod.occ.sample import sample_curve
from surfmod.occ.guard import kernel
from surfmod.occ.sample import distances_to_face


def intersect_surfaces(s1, s2, tolerance: float = 1e-7, samples: int = 200):
    """``GeomAPI_IntSS``: list of ``(points (samples, 3), length)`` per intersection curve."""
    out = []
    with kernel("GeomAPI_IntSS"):
        inter = GeomAPI_IntSS(s1, s2, float(tolerance))
        if not inter.IsDone():
            raise RuntimeError("GeomAPI_IntSS not done")
        for i in range(1, inter.NbLines() + 1):
            c = inter.Line(i)
            t0, t1 = c.FirstParameter(), c.LastParameter()
            out.append((sample_curve(c, t0, t1, samples), curve_length(c, t0, t1)))
    return out


def intersect_line(surf, origin, direction) -> np.ndarray:
    """``GeomAPI_IntCS`` of the line ``origin + w * unit(direction)``: ``(k, 3)`` rows ``(u, v, w)``."""
    with kernel("GeomAPI_IntCS"):
        line = Geom_Line(gp_Lin(arrays.pnt(origin), gp_Dir(*map(float, direction))))
        inter = GeomAPI_IntCS(line, surf)
        if not inter.IsDone():
            raise RuntimeError("GeomAPI_IntCS not done")
        rows = [inter.Parameters(i) for i in range(1, inter.NbPoints() + 1)]
    return np.array(rows, dtype=float).reshape(-1, 3)


def project_points(surf, bounds, points) -> np.ndarray:
    """``GeomAPI_ProjectPointOnSurf`` lower-distance solution per point: ``(N, 3)`` rows
    ``(u, v, distance)``; NaN where OCCT finds no orthogonal projection."""
    u0, u1, v0, v1 = map(float, bounds)
    out = np.full((len(points), 3), np.nan)
    with kernel("GeomAPI_ProjectPointOnSurf"):
        proj = GeomAPI_ProjectPointOnSurf()
        for a, q in enumerate(points):
            proj.Init(arrays.pnt(q), surf, u0, u1, v0, v1)
            if proj.NbPoints() > 0:
                u, v = proj.LowerDistanceParameters()
                out[a] = (u, v, proj.LowerDistance())
    return out


def face_distances(face, points) -> np.ndarray:
    """Distance from each point to a face (``BRepExtrema_DistShapeShape``), boundaries included."""
    return distances_to_face(getattr(face, "wrapped", face), np.asarray(points, dtype=float))


def curve_length(curve, t0: float, t1: float, tol: float = 1e-10) -> float:
    """Arc length by ``GCPnts_AbscissaPoint.Length_s``."""
    with kernel("GCPnts_AbscissaPoint.Length_s"):
        return float(GCPnts_AbscissaPoint.Length_s(GeomAdaptor_Curve(curve, t0, t1), tol))
