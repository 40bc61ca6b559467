"""Lengths and samples of curves and edges (``GCPnts``) and a wire's edges in order."""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_QuasiUniformDeflection
from OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from . import arrays
from .arrays import xyz
from .guard import kernel


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


def curve_length(curve, t0: float, t1: float, tol: float = 1e-10) -> float:
    """Arc length by ``GCPnts_AbscissaPoint.Length_s``."""
    with kernel("GCPnts_AbscissaPoint.Length_s"):
        return float(GCPnts_AbscissaPoint.Length_s(GeomAdaptor_Curve(curve, t0, t1), tol))


def sample_curve(curve, t0: float, t1: float, count: int) -> np.ndarray:
    """``count`` points equally spaced in parameter."""
    with kernel("Geom_Curve.Value"):
        return np.array([arrays.xyz(curve.Value(float(t))) for t in np.linspace(t0, t1, count)])
