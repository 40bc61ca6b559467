"""OCCT's collection classes and the few renamed tools, under one set of names on OCCT 7.9 and 8.0.

This is the door's one version switch: the rest of surfmod imports these names from here,
spelled as OCCT 7.9 spells them, so no other module knows which OCCT it runs on
(:func:`box_limits` reads a ``Bnd_Box`` both bind).  See :doc:`/guide/stacks` (section
"What differs, and where surfmod keeps it").

>>> arr = TColgp_Array1OfPnt(1, 2)
>>> (arr.Lower(), arr.Upper())
(1, 2)
>>> OCCT_VERSION >= (7, 9)
True
>>> from OCP.Bnd import Bnd_Box
>>> from OCP.gp import gp_Pnt
>>> box = Bnd_Box()
>>> box.Add(gp_Pnt(1, 2, 3)); box.Add(gp_Pnt(4, 5, 6))
>>> box_limits(box)
(1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
"""

import OCP
from OCP.IntTools import IntTools_FClass2d

#: The OCCT release OCP was built on, as a tuple of ints: ``(7, 9, 3)`` or ``(8, 0, 1)``.
OCCT_VERSION = tuple(int(part) for part in OCP.__version__.split(".")[:3])

try:  # OCCT 8.0: one template module
    from OCP.collections import (
        Array1_double as TColStd_Array1OfReal,
        Array1_gp_Pnt as TColgp_Array1OfPnt,
        Array1_gp_Pnt2d as TColgp_Array1OfPnt2d,
        Array1_int as TColStd_Array1OfInteger,
        Array2_double as TColStd_Array2OfReal,
        Array2_gp_Pnt as TColgp_Array2OfPnt,
        HSequence_TopoDS_Shape as TopTools_HSequenceOfShape,
        IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as TopTools_IndexedDataMapOfShapeListOfShape,
        IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as TopTools_IndexedMapOfShape,
        List_TopoDS_Shape as TopTools_ListOfShape,
    )
    from OCP.GC import GC_MakeSegment2d as MakeSegment2d
except ImportError:  # OCCT 7.9: the package typedefs
    from OCP.GCE2d import GCE2d_MakeSegment as MakeSegment2d
    from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array1OfPnt2d, TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal
    from OCP.TopTools import (
        TopTools_HSequenceOfShape,
        TopTools_IndexedDataMapOfShapeListOfShape,
        TopTools_IndexedMapOfShape,
        TopTools_ListOfShape,
    )


def box_limits(box) -> tuple:
    """``(xmin, ymin, zmin, xmax, ymax, zmax)`` of a non-void ``Bnd_Box``, its gap included
    (what ``Bnd_Box.Get()`` returns on OCCT 7.9)."""
    return box.CornerMin().Coord() + box.CornerMax().Coord()


__all__ = [
    "OCCT_VERSION",
    "box_limits",
    "IntTools_FClass2d",
    "MakeSegment2d",
    "TColStd_Array1OfInteger",
    "TColStd_Array1OfReal",
    "TColStd_Array2OfReal",
    "TColgp_Array1OfPnt",
    "TColgp_Array1OfPnt2d",
    "TColgp_Array2OfPnt",
    "TopTools_HSequenceOfShape",
    "TopTools_IndexedDataMapOfShapeListOfShape",
    "TopTools_IndexedMapOfShape",
    "TopTools_ListOfShape",
]
