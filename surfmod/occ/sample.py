"""Sampling of OCCT curves and surfaces: per-point values (``D0``/``D1``/``D2``,
``GeomLProp``, ``GeomAPI`` projection), the cross-check's independent side, and lengths
and samples of curves and edges (``GCPnts``) with a wire's edges in order.

These are deliberately plain loops over OCCT calls; they are the reference, not an
evaluation path.
"""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_QuasiUniformDeflection
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt, gp_Vec

from . import arrays
from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .topo import closest_on_face


def surface_d2(surf, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(N, 3, 3, 3)`` derivative squares from ``D2`` (entries with k+l > 2 are NaN)."""
    return _d2_square(surf, u, v, positions_from_value=False)


def surface_d0(surf, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(N, 3)`` positions from ``Value``."""
    with kernel("Geom_Surface.Value"):
        return np.array([xyz(surf.Value(float(uu), float(vv))) for uu, vv in zip(u, v)])


def surface_props(surf, u: np.ndarray, v: np.ndarray, resolution: float = 1e-9):
    """Normals ``(N, 3)`` (NaN where undefined) and curvatures ``(N, 4)`` = (K, H, max, min)
    from ``GeomLProp_SLProps`` (NaN where undefined).  Coordinates are collected as
    tuples per point and converted to arrays once at the end (the per-point Python cost
    dominates this loop)."""
    nan3, nan4 = (np.nan,) * 3, (np.nan,) * 4
    normals: list = []
    curv: list = []
    with kernel("GeomLProp_SLProps"):
        props = GeomLProp_SLProps(surf, 2, resolution)
        set_params, normal_ok, curv_ok = props.SetParameters, props.IsNormalDefined, props.IsCurvatureDefined
        for uu, vv in zip(np.asarray(u, dtype=float).tolist(), np.asarray(v, dtype=float).tolist()):
            set_params(uu, vv)
            normals.append(props.Normal().Coord() if normal_ok() else nan3)
            curv.append((props.GaussianCurvature(), props.MeanCurvature(), props.MaxCurvature(), props.MinCurvature())
                        if curv_ok() else nan4)
    return np.array(normals, dtype=float).reshape(-1, 3), np.array(curv, dtype=float).reshape(-1, 4)


def curve_d2(curve, t: np.ndarray) -> np.ndarray:
    """``(N, 3, 3)`` position, first and second derivative from ``D2``."""
    out = np.empty((len(t), 3, 3))
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    with kernel("Geom_Curve.D2"):
        for a, tt in enumerate(t):
            curve.D2(float(tt), p, d1, d2)
            out[a] = (xyz(p), xyz(d1), xyz(d2))
    return out


def distances_to_face(face_shape, points: np.ndarray) -> np.ndarray:
    """Distance from each point to a TopoDS face, boundary included
    (``BRepExtrema_DistShapeShape``; see :func:`surfmod.occ.topo.closest_on_face`)."""
    return closest_on_face(face_shape, np.asarray(points, dtype=float).reshape(-1, 3))[0]


def distances_to_surface(surf, points: np.ndarray, bounds) -> np.ndarray:
    """Distance from each point to a bounded ``Geom_Surface`` (``GeomAPI_ProjectPointOnSurf``),
    falling back to the face distance when projection finds no extremum (e.g. at borders)."""
    u0, u1, v0, v1 = bounds
    out = np.empty(len(points))
    with kernel("GeomAPI_ProjectPointOnSurf"):
        proj = GeomAPI_ProjectPointOnSurf()
        for a, q in enumerate(points):
            proj.Init(gp_Pnt(*map(float, q)), surf, u0, u1, v0, v1)
            out[a] = proj.LowerDistance() if proj.NbPoints() > 0 else np.nan
    return out


def surface_values_d2(surf, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """:func:`surface_d2` with positions from ``Value`` (exact even where ``D2`` loses
    digits): the same numbers as ``surface_d2`` + ``surface_d0`` in one loop."""
    return _d2_square(surf, u, v, positions_from_value=True)


def _d2_square(surf, u, v, positions_from_value: bool) -> np.ndarray:
    """The loop of :func:`surface_d2`, with as little Python per point as OCP allows:
    coordinates are collected as tuples (``Coord``) and converted to one array at the end."""
    n = len(u)
    flat: list = []
    add = flat.extend
    p = gp_Pnt()
    d1u, d1v, d2u, d2v, d2uv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    d2, value = surf.D2, surf.Value
    with kernel("Geom_Surface.D2"):
        for uu, vv in zip(np.asarray(u, dtype=float).tolist(), np.asarray(v, dtype=float).tolist()):
            d2(uu, vv, p, d1u, d1v, d2u, d2v, d2uv)
            add(value(uu, vv).Coord() if positions_from_value else p.Coord())
            add(d1u.Coord())
            add(d1v.Coord())
            add(d2u.Coord())
            add(d2v.Coord())
            add(d2uv.Coord())
    rows = np.array(flat, dtype=float).reshape(n, 6, 3)
    out = np.full((n, 3, 3, 3), np.nan)
    out[:, 0, 0], out[:, 1, 0], out[:, 0, 1] = rows[:, 0], rows[:, 1], rows[:, 2]
    out[:, 2, 0], out[:, 0, 2], out[:, 1, 1] = rows[:, 3], rows[:, 4], rows[:, 5]
    return out


def wire_edges(wire):
    """The edges of a wire in connection order."""
    out = []
    ex = BRepTools_WireExplorer(TopoDS.Wire(getattr(wire, "wrapped", wire)))
    while ex.More():
        out.append(ex.Current())
        ex.Next()
    return out


def edge_points(edge, deflection: float) -> np.ndarray:
    """Points along an edge (in its orientation) whose chords stay within ``deflection``
    of the curve (``GCPnts_QuasiUniformDeflection``)."""
    with kernel("GCPnts_QuasiUniformDeflection"):
        c = BRepAdaptor_Curve(edge)
        algo = GCPnts_QuasiUniformDeflection(c, float(deflection), c.FirstParameter(), c.LastParameter())
        if not algo.IsDone():
            raise SurfmodError("tolerance: OCCT could not discretize a section edge at this deflection")
        pts = np.array([xyz(algo.Value(i)) for i in range(1, algo.NbPoints() + 1)])
    return pts[::-1] if edge.Orientation() == TopAbs_REVERSED else pts


def edge_length(edge) -> float:
    """Length of an edge (``GCPnts_AbscissaPoint``, OCCT's own)."""
    with kernel("GCPnts_AbscissaPoint.Length_s"):
        return float(GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(edge), 1e-12))


def sample_curve(curve, t0: float, t1: float, count: int) -> np.ndarray:
    """``count`` points equally spaced in parameter."""
    with kernel("Geom_Curve.Value"):
        return np.array([arrays.xyz(curve.Value(float(t))) for t in np.linspace(t0, t1, count)])
