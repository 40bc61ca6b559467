"""OCCT analytic curves (lines, circles) with surfmod's parametrizations."""

from __future__ import annotations

from OCP.Geom import Geom_Line, Geom_TrimmedCurve
from OCP.gp import gp_Dir, gp_Lin

from .arrays import pnt
from .guard import kernel


def line(origin, direction, length) -> Geom_TrimmedCurve:
    """Arc-length line from ``origin`` trimmed to ``[0, length]``."""
    with kernel("Geom_Line"):
        base = Geom_Line(gp_Lin(pnt(origin), gp_Dir(*map(float, direction))))
        return Geom_TrimmedCurve(base, 0.0, float(length))
