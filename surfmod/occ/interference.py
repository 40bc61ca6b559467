"""The kernel side of interference (the same concept as :mod:`surfmod.uses.interference`,
one level down): the ``BRepAlgoAPI_Common`` volume of two parts and their
``BRepExtrema_DistShapeShape`` distance."""

from __future__ import annotations

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
from OCP.BRepExtrema import BRepExtrema_DistShapeShape

from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .properties import gprops
from .topo import solids_of


def common_volume(a, b, eps: float = 1e-9) -> float:
    """Volume of ``BRepAlgoAPI_Common(a, b)`` (0 when the parts do not overlap)."""
    with kernel("BRepAlgoAPI_Common"):
        op = BRepAlgoAPI_Common(a, b)
        if not op.IsDone():
            raise SurfmodError("a, b: OCCT boolean common failed on these parts")
        result = op.Shape()
    if result is None or result.IsNull() or not solids_of(result):
        return 0.0
    return float(gprops(result, eps)["volume"])


def min_distance(a, b):
    """``(distance, point_on_a, point_on_b, inner)`` from ``BRepExtrema_DistShapeShape``."""
    with kernel("BRepExtrema_DistShapeShape"):
        d = BRepExtrema_DistShapeShape(a, b)
        if not d.IsDone() or d.NbSolution() == 0:
            raise SurfmodError("a, b: OCCT could not compute the minimum distance")
        return float(d.Value()), xyz(d.PointOnShape1(1)), xyz(d.PointOnShape2(1)), bool(d.InnerSolution())
