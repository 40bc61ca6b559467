"""OCCT's swept and lofted shells: ``BRepOffsetAPI_MakePipeShell`` and
``BRepOffsetAPI_ThruSections``, built from OCCT curves (``Geom_Curve`` + range).

The same concept as :mod:`surfmod.construct.sweep`, of which this is the OCCT twin.
"""

from __future__ import annotations

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
from OCP.BRepFill import BRepFill_TypeOfContact
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakePipeShell, BRepOffsetAPI_ThruSections
from OCP.gp import gp_Pnt2d
from OCP.Law import Law_Interpol
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..errors import KernelError
from .bindings import TColgp_Array1OfPnt2d
from .guard import check_done, kernel
from .topo import faces_of


def _wire(curve, t0, t1):
    edge = BRepBuilderAPI_MakeEdge(curve, float(t0), float(t1))
    check_done(edge, "BRepBuilderAPI_MakeEdge")
    wire = BRepBuilderAPI_MakeWire(edge.Edge())
    check_done(wire, "BRepBuilderAPI_MakeWire")
    return wire.Wire()


def pipe_shell(profiles, path, *, mode: str = "frenet", auxiliary=None, contact: bool = False,
               tolerance: float = 1e-6, max_degree: int = 11, max_segments: int = 200, scale_law=None):
    """A pipe shell: ``profiles`` is one ``(curve, t0, t1)`` (placed at the path start) or
    two (start and end of the path); ``path`` is ``(curve, t0, t1)``.

    ``mode``: ``"frenet"`` / ``"corrected_frenet"`` (OCCT's trihedron laws) or
    ``"auxiliary"`` with ``auxiliary=(curve, t0, t1)``: the normal points at the
    auxiliary spine (found in the normal plane of the spine, no curvilinear
    equivalence); ``contact`` keeps the profile touching it (scaled).  ``scale_law`` =
    ``(spine_params, factors)`` scales the (single) profile homothetically along the
    spine (``SetLaw`` with a ``Law_Interpol``).  Returns the shell (``TopoDS_Shape``) and
    its faces.
    """
    with kernel("BRepOffsetAPI_MakePipeShell"):
        spine = _wire(*path)
        first, last = TopoDS.Vertex(TopExp.FirstVertex_s(_edge_of(spine))), TopoDS.Vertex(
            TopExp.LastVertex_s(_edge_of(spine))
        )
        maker = BRepOffsetAPI_MakePipeShell(spine)
        if mode == "frenet":
            maker.SetMode(True)
        elif mode == "corrected_frenet":
            maker.SetMode(False)
        elif mode == "auxiliary":
            kind = BRepFill_TypeOfContact.BRepFill_ContactOnBorder if contact else BRepFill_TypeOfContact.BRepFill_NoContact
            maker.SetMode(_wire(*auxiliary), False, kind)
        else:  # pragma: no cover - callers validate
            raise KernelError(f"pipe_shell: unknown mode {mode!r}")
        maker.SetTolerance(float(tolerance), float(tolerance), 1e-4)
        maker.SetMaxDegree(int(max_degree))
        maker.SetMaxSegments(int(max_segments))
        if scale_law is not None:
            maker.SetLaw(_wire(*profiles[0]), _interpolated_law(*scale_law), first, False, False)
        else:
            for k, prof in enumerate(profiles):
                maker.Add(_wire(*prof), first if k == 0 else last, False, False)
        maker.Build()
        check_done(maker, "BRepOffsetAPI_MakePipeShell")
        shape = maker.Shape()
    return shape, _faces(shape, "BRepOffsetAPI_MakePipeShell")


def thru_sections(sections, *, ruled: bool, tolerance: float = 1e-6):
    """``BRepOffsetAPI_ThruSections`` through ``[(curve, t0, t1), ...]`` (a shell, not a
    solid); returns ``(shape, faces)``."""
    with kernel("BRepOffsetAPI_ThruSections"):
        maker = BRepOffsetAPI_ThruSections(False, bool(ruled), float(tolerance))
        maker.CheckCompatibility(False)
        for sec in sections:
            maker.AddWire(_wire(*sec))
        maker.Build()
        check_done(maker, "BRepOffsetAPI_ThruSections")
        shape = maker.Shape()
    return shape, _faces(shape, "BRepOffsetAPI_ThruSections")


def _faces(shape, maker: str):
    """The faces of a maker's result; a result without any is a kernel failure."""
    faces = faces_of(shape)
    if not faces:
        raise KernelError(f"{maker}: the result has no face")
    return faces


def _interpolated_law(params, values):
    arr = TColgp_Array1OfPnt2d(1, len(params))
    for i, (a, b) in enumerate(zip(params, values), start=1):
        arr.SetValue(i, gp_Pnt2d(float(a), float(b)))
    law = Law_Interpol()
    law.Set(arr, False)
    return law


def _edge_of(wire):
    explorer = TopExp_Explorer(wire, TopAbs_EDGE)
    return TopoDS.Edge(explorer.Current())
