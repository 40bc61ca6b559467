"""OCCT's Boolean operations (``BRepAlgoAPI``, ``BOPAlgo``): plane sections of shapes (for
:mod:`surfmod.uses.section`), the common volume of two parts with their ``BRepExtrema``
distance (for :mod:`surfmod.uses.interference`), and the material regions of a solid whose
boundary touches itself (``BOPAlgo_MakerVolume``, the regions on the material side of the
original faces).  See :doc:`/guide/uses` (section "Finite element meshes").
"""

from __future__ import annotations

import numpy as np
from OCP.BOPAlgo import BOPAlgo_MakerVolume
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Section
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.GeomAbs import GeomAbs_Plane
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SOLID
from OCP.TopoDS import TopoDS

from ..errors import KernelError, SurfmodError
from .arrays import xyz
from .bindings import TopTools_HSequenceOfShape, TopTools_ListOfShape
from .guard import kernel
from .properties import gprops
from .topo import explore, faces_of, solids_of, wrapped


def cut_edges(shape, origin, normal) -> list:
    """The edges of ``BRepAlgoAPI_Section`` of ``shape`` by the plane ``(origin,
    normal)``; ``SurfmodError`` when OCCT fails."""
    with kernel("BRepAlgoAPI_Section"):
        op = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(*map(float, origin)), gp_Dir(*map(float, normal))), False)
        op.Approximation(False)
        op.ComputePCurveOn1(False)
        op.Build()
        if not op.IsDone():
            raise SurfmodError("obj: OCCT could not section this shape")
        return explore(op.Shape(), TopAbs_EDGE)


def wires_of(edges) -> list:
    """``edges`` chained end to end into build123d ``Wire`` s (``ShapeAnalysis_FreeBounds``)."""
    import build123d as bd

    with kernel("ShapeAnalysis_FreeBounds (section wires)"):
        seq = TopTools_HSequenceOfShape()
        for e in edges:
            seq.Append(e)
        wires = TopTools_HSequenceOfShape()
        ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(seq, 1e-6, False, wires)
        return [bd.Wire(TopoDS.Wire(wires.Value(i))) for i in range(1, wires.Length() + 1)]


def planar_faces_on(shape, origin, normal, tol: float) -> list[int]:
    """Exploration indices of the planar faces of ``shape`` that lie in the plane
    ``(origin, normal)`` (parallel within 1e-9, offset within ``tol``): OCCT's plane of
    each face, with the face's location applied (``BRepAdaptor_Surface``)."""
    origin, normal = np.asarray(origin, dtype=float), np.asarray(normal, dtype=float)
    out = []
    with kernel("BRepAdaptor_Surface (planar faces)"):
        for i, face in enumerate(faces_of(shape)):
            adaptor = BRepAdaptor_Surface(face, False)
            if adaptor.GetType() != GeomAbs_Plane:
                continue
            ax = adaptor.Plane().Axis()
            z, o = xyz(ax.Direction()), xyz(ax.Location())
            if abs(abs(float(z @ normal)) - 1.0) < 1e-9 and abs(float((o - origin) @ normal)) < tol:
                out.append(i)
    return out


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


#: The regions' BRepGProp volumes must add up to the solid's within this relative error
#: (both at eps 1e-9): anything else means a region was misclassified or lost.
VOLUME_AGREEMENT = 1e-7


def material_regions(solid) -> list:
    """The solid's material split into regions with manifold, non-crossing boundaries
    (``TopoDS_Solid`` list): the volumes ``BOPAlgo_MakerVolume`` builds from the solid's
    faces, kept where their faces keep the orientation the solid gives them (the
    material side); voids and outside pockets the faces enclose are dropped.  Raises
    ``KernelError`` when OCCT fails or the kept volumes do not add up to the solid's.

    >>> import build123d as bd
    >>> from surfmod.occ.properties import gprops
    >>> hollow = bd.Box(4, 4, 4) - bd.Box(2, 2, 2)  # a solid with an inner void shell
    >>> [round(gprops(r)["volume"], 9) for r in material_regions(hollow.wrapped)]
    [56.0]
    """
    solid = wrapped(solid)
    with kernel("BOPAlgo_MakerVolume (material regions)"):
        maker = BOPAlgo_MakerVolume()
        maker.SetRunParallel(False)  # the machine's cores belong to the caller
        maker.SetIntersect(True)
        faces = list(explore(solid, TopAbs_FACE))
        arguments = TopTools_ListOfShape()
        for face in faces:
            arguments.Append(face)
        maker.SetArguments(arguments)
        maker.Perform()
        if maker.HasErrors():
            raise KernelError("BOPAlgo_MakerVolume (material regions): OCCT reported errors")
        # each image face, as oriented in the solid's own faces: material lies behind it
        side: dict = {}  # shape hash (orientation-blind) -> the images with that hash
        for face in faces:
            for image in list(maker.Modified(face)) or [face]:
                side.setdefault(image.__hash__(), []).append(image)

        def same_side(face):
            for image in side.get(face.__hash__(), ()):
                if image.IsSame(face):
                    return face.Orientation() == image.Orientation()
            return None

        kept = []
        for region in explore(maker.Shape(), TopAbs_SOLID):
            votes = [v for v in map(same_side, explore(region, TopAbs_FACE)) if v is not None]
            if votes and all(votes):
                kept.append(region)
            elif any(votes):
                raise KernelError("BOPAlgo_MakerVolume (material regions): a region lies on both sides of the solid's faces")
    kept = [s for r in kept for s in solids_of(r)]
    total = sum(abs(gprops(r)["volume"]) for r in kept)
    expected = abs(gprops(solid)["volume"])
    if not kept or abs(total - expected) > VOLUME_AGREEMENT * expected:
        raise KernelError(f"BOPAlgo_MakerVolume (material regions): the regions hold {total:.10g}, "
                          f"the solid {expected:.10g}")
    return kept
