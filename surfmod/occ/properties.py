"""``BRepGProp``: volume, area, centroid and inertia of shapes (plain, about a chosen point,
by the Gauss–Kronrod rule, on faces split by ``ShapeUpgrade``), the vertex mean BRepGProp refers its integrals to, and the one bounding
box of the kernel door (``BRepBndLib``).  The references built on these calls, and their
verdict, are :mod:`surfmod.uses.mass_reference`."""

from __future__ import annotations

from itertools import chain

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepGProp import BRepGProp, BRepGProp_Domain, BRepGProp_Face, BRepGProp_Vinert
from OCP.GProp import GProp_GProps
from OCP.ShapeUpgrade import ShapeUpgrade_ShapeDivideArea
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_VERTEX
from OCP.gp import gp_Pnt
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .bindings import box_limits, TopTools_IndexedDataMapOfShapeListOfShape
from .topo import faces_of, solids_of, wrapped


def gprops(shape, eps: float = 1e-9, inside_out: list | None = None) -> dict:
    """``BRepGProp`` volume and surface properties at relative tolerance ``eps``.

    Returns volume, area, centroid and the inertia matrix about the centroid
    (OCCT's ``MatrixOfInertia``: diagonal ``∫(y²+z²)``, off-diagonal ``−∫xy``).

    With ``inside_out`` (a list) each solid of ``shape`` is measured apart and one whose
    volume comes out negative (its faces point into its material) is measured again
    turned outward, its ``(number from 1, volume)`` appended: the volume pass that
    orients the solids is the one measured (the second only for a solid inside out).
    """
    with kernel("BRepGProp.VolumeProperties_s"):
        vp = GProp_GProps()
        if inside_out is None:
            verr = BRepGProp.VolumeProperties_s(shape, vp, float(eps), False, False)
        else:
            parts = []
            for number, solid in enumerate(solids_of(shape), 1):
                part = GProp_GProps()
                err = BRepGProp.VolumeProperties_s(solid, part, float(eps), False, False)
                if part.Mass() < 0:
                    inside_out.append((number, part.Mass()))
                    part = GProp_GProps()
                    err = BRepGProp.VolumeProperties_s(solid.Reversed(), part, float(eps), False, False)
                parts.append((part, err))
            if len(parts) == 1:  # one solid: its own figures, bit for bit as without ``inside_out``
                vp, verr = parts[0]
            else:  # BRepGProp's error is relative: the solids' absolute errors summed, over the volume
                for part, _ in parts:
                    vp.Add(part)
                verr = sum(abs(err * part.Mass()) for part, err in parts) / vp.Mass() if parts else 0.0
        sp = GProp_GProps()
        serr = BRepGProp.SurfaceProperties_s(shape, sp, float(eps), False)
    return {
        "volume": vp.Mass(),
        "area": sp.Mass(),
        "centroid": xyz(vp.CentreOfMass()),
        "inertia": inertia_matrix(vp),
        "volume_error": verr,
        "area_error": serr,
    }


def inertia_matrix(props: GProp_GProps) -> np.ndarray:
    """``props.MatrixOfInertia()`` as a ``(3, 3)`` array (about the centre of mass)."""
    m = props.MatrixOfInertia()
    return np.array([[m.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)])


def solid_figures(solid):
    """Volume and centroid of one solid (area and centroid of a face) by BRepGProp's fixed
    Gauss rule (the same digits for the same geometry, so a change is the geometry's)."""
    with kernel("BRepGProp.VolumeProperties_s"):
        vp = GProp_GProps()
        (BRepGProp.SurfaceProperties_s if solid.ShapeType() == TopAbs_FACE else BRepGProp.VolumeProperties_s)(solid, vp)
    return vp.Mass(), xyz(vp.CentreOfMass())


def vertex_mean(shape) -> np.ndarray:
    """Mean of the shape's vertex points, visited with repeats as ``TopExp_Explorer`` does
    (BRepGProp's rough barycentre, the reference point of its integrals); the bounding
    box centre when the shape has no vertex (one periodic face: a full sphere).

    The explorer meets a vertex once per occurrence under an edge occurrence (an edge
    once per face that holds it), which is the length of its ancestor list in
    ``TopExp::MapShapesAndAncestors(VERTEX, EDGE)`` (one entry per such occurrence): each
    distinct vertex is read once and repeated that many times (a vertex under no edge,
    once), instead of one OCCT call chain per visit.

    >>> import build123d as bd
    >>> vertex_mean(bd.Box(2, 4, 6).wrapped).round(12).tolist()  # 8 corners, 6 visits each
    [0.0, 0.0, 0.0]
    """
    with kernel("TopExp.MapShapesAndAncestors_s"):
        ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
        TopExp.MapShapesAndAncestors_s(shape, TopAbs_VERTEX, TopAbs_EDGE, ancestors)
        n = ancestors.Extent()
        if not n:
            return bounding_box(shape).mean(axis=0)
        pnt, vertex, key, edges = BRep_Tool.Pnt_s, TopoDS.Vertex, ancestors.FindKey, ancestors.FindFromIndex
        # one flat fromiter over Coord() tuples (no array per vertex)
        pts = np.fromiter(chain.from_iterable(pnt(vertex(key(i))).Coord() for i in range(1, n + 1)), float, 3 * n)
        visits = np.fromiter((edges(i).Size() for i in range(1, n + 1)), int, n)
    return np.repeat(pts.reshape(n, 3), np.maximum(visits, 1), axis=0).mean(axis=0)


def bounding_box(shape, *, optimal: bool = True) -> np.ndarray:
    """``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` of a ``TopoDS_Shape`` or build123d
    shape: the tight box (``BRepBndLib.AddOptimal``), or with ``optimal=False`` OCCT's quick
    box (from a stored triangulation, else the control points, enlarged by the shape
    tolerance: a cheap upper bound).  The one bounding box of the kernel door."""
    inner = wrapped(shape)
    shape = shape if inner is None else inner
    with kernel("BRepBndLib.AddOptimal_s" if optimal else "BRepBndLib.Add"):
        box = Bnd_Box()
        if optimal:
            BRepBndLib.AddOptimal_s(shape, box, False, False)
        else:
            BRepBndLib.Add_s(shape, box, True)
        return np.array(box_limits(box)).reshape(2, 3)


def check_coordinates(shape, path, max_coordinate: float) -> None:
    """Raise ``SurfmodError`` naming ``path`` when ``shape`` holds no geometry, or NaN,
    infinite or out-of-range coordinates (beyond ``max_coordinate``) in its box from the
    geometry (the STEP reader's last check).  The box holds every pole of a B-spline or
    Bézier face, not only its edges (``BndLib_AddSurface``), and the reader's text scan
    (:func:`surfmod.checks.step_file`) has refused NaN, infinity and numbers beyond
    1e70 before OCCT read the file: no number inside a face escapes both."""
    with kernel("BRepBndLib"):
        box = Bnd_Box()
        BRepBndLib.Add_s(shape, box, False)  # from the geometry, not a triangulation
        if box.IsVoid():
            raise SurfmodError(f"path: {path} contains no geometry")
        corners = box_limits(box)
    if not all(np.isfinite(corners)):
        raise SurfmodError(f"path: {path} has NaN or infinite coordinates")
    size = max(abs(c) for c in corners)
    if size > max_coordinate:
        raise SurfmodError(f"path: {path} has coordinates up to {size:.3g}, beyond the limit {max_coordinate:.3g} "
                           "(max_coordinate=)")


def split_faces(shape, k: int):
    """``shape`` with every face split into about ``k × k`` pieces along iso-parametric lines
    of its surface (``ShapeUpgrade_ShapeDivideArea`` by numbers: the same surfaces and
    p-curve pieces; ``k = 1``, or nothing to split: the shape itself)."""
    if k == 1:
        return shape
    with kernel("ShapeUpgrade_ShapeDivideArea"):
        divide = ShapeUpgrade_ShapeDivideArea(shape)
        divide.SetSplittingByNumber(True)
        divide.SetNumbersUVSplits(k, k)
        if not divide.Perform():
            return shape  # nothing to split (one planar face, say): the shape as it is
        return divide.Result()


def gprops_about(shape, location, eps: float = 1e-13) -> dict:
    """``volume``, ``area``, ``centroid`` and ``inertia`` (as :func:`gprops`) with the volume
    integrals taken face by face as ``BRepGProp::VolumeProperties`` takes them (forward and
    reversed faces, the domain of a trimmed face, ``BRepGProp_Vinert``'s adaptive rule at
    ``eps``), but about the point ``location`` the caller chooses (the area is the same
    about any point)."""
    total = GProp_GProps(gp_Pnt(0, 0, 0))
    with kernel("BRepGProp_Vinert"):
        vinert = BRepGProp_Vinert()
        vinert.SetLocation(gp_Pnt(*map(float, location)))
        for face in faces_of(shape):
            if face.Orientation() not in (TopAbs_FORWARD, TopAbs_REVERSED):
                continue  # internal and external faces bound no volume
            bf = BRepGProp_Face()
            bf.Load(face)
            domain = BRepGProp_Domain()
            if face.NbChildren() != 0:
                domain.Init(face)
            vinert.Perform(bf, domain, float(eps))
            total.Add(vinert, 1.0)
        area = GProp_GProps()
        BRepGProp.SurfaceProperties_s(shape, area, float(eps), False)
    return {"volume": total.Mass(), "area": area.Mass(), "centroid": xyz(total.CentreOfMass()),
            "inertia": inertia_matrix(total)}


def gauss_kronrod(shape, eps: float) -> dict:
    """:func:`gprops_about`'s figures by ``BRepGProp::VolumePropertiesGK`` with its centroid
    and inertia flags set (the adaptive Gauss–Kronrod rule refines each face until the
    volume *and* the moments have converged to ``eps``) about BRepGProp's own point, the
    area by ``SurfaceProperties`` at the same ``eps``, and ``error``: the rule's estimate of
    its relative error (negative when it failed)."""
    with kernel("BRepGProp.VolumePropertiesGK_s"):
        props = GProp_GProps()
        error = BRepGProp.VolumePropertiesGK_s(shape, props, float(eps), False, True, True, True)
        area = GProp_GProps()
        BRepGProp.SurfaceProperties_s(shape, area, float(eps), False)
    return {"volume": props.Mass(), "area": area.Mass(), "centroid": xyz(props.CentreOfMass()),
            "inertia": inertia_matrix(props), "error": float(error)}
