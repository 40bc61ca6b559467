"""OCCT side of the "uses" of surface models: solids, mass properties (``BRepGProp``),
booleans (``BRepAlgoAPI``), distances (``BRepExtrema``), planar sections, BREP/STEP I/O
for gmsh, and the per-face data the NumPy quadrature needs.

Everything here returns plain Python/NumPy data; the NumPy work lives in
``surfmod/uses``.
"""

from __future__ import annotations

from itertools import chain

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from .arrays import xyz
from .guard import check_done, kernel
from .topo import explore as _explore, geometric_edges, pcurve_points, shells_of, solids_of, wrapped
from OCP.BRep import BRep_Builder
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Section
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepLib import BRepLib
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.Bnd import Bnd_Box
from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_QuasiUniformDeflection
from OCP.GProp import GProp_GProps
from OCP.GeomAbs import GeomAbs_Plane
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds, ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopTools import TopTools_HSequenceOfShape, TopTools_IndexedDataMapOfShapeListOfShape
from OCP.TopoDS import TopoDS_Shell
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from .exchange import compound
from .topo import faces_of
import OCP.Geom as G

SEW_TOLERANCE = 1e-6


def model_tolerance(shape) -> float:
    """The largest edge tolerance of ``shape`` (what the writing system vouched for)."""
    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1, TopAbs_EDGE))


def sew_solid(face_shapes, tolerance: float = SEW_TOLERANCE):
    """Sew faces into a closed shell and make an outward-oriented solid.

    Raises ``SurfmodError`` when the faces do not close up.
    """
    with kernel("BRepBuilderAPI_Sewing"):
        sewing = BRepBuilderAPI_Sewing(tolerance)
        for f in face_shapes:
            sewing.Add(f)
        sewing.Perform()
        sewed = sewing.SewedShape()
    shells = shells_of(sewed)
    if len(shells) != 1 or not BRep_Tool.IsClosed_s(shells[0]):
        raise SurfmodError(
            f"obj: the {len(face_shapes)} faces do not sew into one closed shell at tolerance {tolerance:.3g} "
            f"(got {len(shells)} shell(s), free edges remain): volume needs a closed boundary"
        )
    with kernel("BRepBuilderAPI_MakeSolid"):
        maker = BRepBuilderAPI_MakeSolid(shells[0])
        check_done(maker, "BRepBuilderAPI_MakeSolid")
        solid = maker.Solid()
        BRepLib.OrientClosedSolid_s(solid)
    return solid


def _solid_of_shell(shell, what: str):
    """A solid bounded by one shell; an open shell is sewn at the model's own tolerance
    first (loose faces that OCCT sewing joins), and refused only if it stays open."""
    if not BRep_Tool.IsClosed_s(shell):
        tol = max(SEW_TOLERANCE, model_tolerance(shell))
        try:
            return sew_solid(_explore(shell, TopAbs_FACE), tol)
        except SurfmodError:
            raise SurfmodError(f"obj: {what} is not closed (free edges remain after sewing at the model's tolerance "
                               f"{tol:.3g}): volume needs a closed boundary") from None
    with kernel("BRepBuilderAPI_MakeSolid"):
        solid = BRepBuilderAPI_MakeSolid(shell).Solid()
        BRepLib.OrientClosedSolid_s(solid)
    return solid


def closed_solid(shape):
    """A closed solid (or compound of them) for volume work; open shells are sewn at the
    model's tolerance and refused if they stay open."""
    solids = solids_of(shape)
    if solids:
        out = []
        for i, s in enumerate(solids):
            shells = shells_of(s)
            if all(BRep_Tool.IsClosed_s(sh) for sh in shells):
                out.append(s)
            elif len(shells) == 1:
                out.append(_solid_of_shell(shells[0], f"solid {i}"))
            else:
                raise SurfmodError(f"obj: solid {i} has an open shell among {len(shells)} (free edges): "
                                   "volume needs a closed boundary")
        return out[0] if len(out) == 1 else compound(out)
    shells = shells_of(shape)
    if shells:
        out = [_solid_of_shell(sh, f"shell {i}") for i, sh in enumerate(shells)]
        return out[0] if len(out) == 1 else compound(out)
    faces = _explore(shape, TopAbs_FACE)
    if not faces:
        raise SurfmodError("obj: has no faces, so no solid to measure")
    # faces that already share their edges (e.g. one periodic face: a full sphere or
    # torus closed by its own seam and poles) form a closed shell without sewing

    builder = BRep_Builder()
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    for f in faces:
        builder.Add(shell, f)
    if BRep_Tool.IsClosed_s(shell):
        return _solid_of_shell(shell, "the shell of its faces")
    return sew_solid(faces, max(SEW_TOLERANCE, model_tolerance(shape)))


def gprops(shape, eps: float = 1e-9) -> dict:
    """``BRepGProp`` volume and surface properties at relative tolerance ``eps``.

    Returns volume, area, centroid and the inertia matrix about the centroid
    (OCCT's ``MatrixOfInertia``: diagonal ``∫(y²+z²)``, off-diagonal ``−∫xy``).
    """
    with kernel("BRepGProp.VolumeProperties_s"):
        vp = GProp_GProps()
        verr = BRepGProp.VolumeProperties_s(shape, vp, float(eps), False, False)
        sp = GProp_GProps()
        serr = BRepGProp.SurfaceProperties_s(shape, sp, float(eps), False)
        c = vp.CentreOfMass()
        m = vp.MatrixOfInertia()
        inertia = np.array([[m.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)])
    return {
        "volume": vp.Mass(),
        "area": sp.Mass(),
        "centroid": xyz(c),
        "inertia": inertia,
        "volume_error": verr,
        "area_error": serr,
    }


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
        pnt, vertex, key, edges = BRep_Tool.Pnt_s, TopoDS.Vertex_s, ancestors.FindKey, ancestors.FindFromIndex
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
        return np.array(box.Get()).reshape(2, 3)


# -- per-face data for the NumPy quadrature ---------------------------------------------
def elementary_faces(faces) -> list:
    """Per ``TopoDS_Face`` of ``faces`` (a part's, for the mass integrals): ``None`` unless
    its surface is a plane, cylinder, cone, sphere or torus (or a
    ``Geom_RectangularTrimmedSurface`` of one), else ``(type name, located surface handle,
    (u0, u1, v0, v1), reversed, frame (4, 3), radii, periodic)`` -- what
    :func:`surfmod.from_face` reads for it (the same OCCT calls and values), without its
    general dispatch, which costs more than the reading on parts of many small faces.
    ``type name`` is the elementary surface's (the basis of a trimmed one), ``periodic``
    whether the face's own surface is periodic in ``u`` and ``v`` (a rectangular trim may
    make it not).

    >>> import build123d as bd
    >>> [(d[0], d[5]) for d in elementary_faces([f.wrapped for f in bd.Cylinder(1, 2).faces()])]
    [('Geom_CylindricalSurface', (1.0,)), ('Geom_Plane', ()), ('Geom_Plane', ())]
    """
    surface_of, uv_bounds = BRep_Tool.Surface_s, BRepTools.UVBounds_s
    reversed_ = TopAbs_REVERSED
    out, frames = [], []
    with kernel("reading elementary faces"):
        for face in faces:
            geom = surface_of(face)  # OCP hands back the derived type already (no DownCast)
            name = geom.DynamicType().Name()
            periodic = _PERIODIC.get(name)
            basis = geom
            if name == "Geom_RectangularTrimmedSurface":
                basis = geom.BasisSurface()
                name = basis.DynamicType().Name()
                periodic = (geom.IsUPeriodic(), geom.IsVPeriodic()) if name in _PERIODIC else None
            if periodic is None:
                out.append(None)
                continue
            if type(basis).__name__ != name:  # an older OCP: the generic handle
                basis = getattr(G, name).DownCast(basis)
            pos = basis.Position()
            frames.append(pos.Location().Coord() + pos.XDirection().Coord() + pos.YDirection().Coord()
                          + pos.Direction().Coord())
            if name == "Geom_Plane":
                radii = ()
            elif name == "Geom_ConicalSurface":
                radii = (basis.RefRadius(), basis.SemiAngle())
            elif name == "Geom_ToroidalSurface":
                radii = (basis.MajorRadius(), basis.MinorRadius())
            else:
                radii = (basis.Radius(),)
            out.append([name, geom, uv_bounds(face), face.Orientation() == reversed_, None, radii, periodic])
    frames = np.array(frames).reshape(-1, 4, 3)  # one array for all frames
    k = 0
    for d in out:
        if d is not None:
            d[4] = frames[k]
            k += 1
    return [None if d is None else tuple(d) for d in out]


# which directions of OCCT's elementary surfaces are periodic (their ``IsUPeriodic``,
# ``IsVPeriodic``; the period is 2π), known without asking
_PERIODIC = {"Geom_Plane": (False, False), "Geom_CylindricalSurface": (True, False),
             "Geom_ConicalSurface": (True, False), "Geom_SphericalSurface": (True, False),
             "Geom_ToroidalSurface": (True, True)}


def edge_deviations(shape, samples: int = 23) -> np.ndarray:
    """``(E, 2)``: per edge of ``shape`` the largest distance between its 3-D curve and the
    image of its p-curve on each of its faces (``samples`` points, as ``BRepCheck`` does),
    and the edge's length.  A model whose edges are off their faces this far bounds a
    region only up to that distance."""
    out = []
    with kernel("edge deviations"):
        for _, edge, edge_faces in geometric_edges(shape):
            c3 = BRepAdaptor_Curve(edge)
            t = np.linspace(c3.FirstParameter(), c3.LastParameter(), samples)
            p3 = np.array([xyz(c3.Value(float(x))) for x in t])
            dev = 0.0
            for face in edge_faces:
                _, ps = pcurve_points(edge, face, samples)
                dev = max(dev, float(np.linalg.norm(ps - p3, axis=1).max()))
            props = GProp_GProps()
            BRepGProp.LinearProperties_s(edge, props)
            out.append((dev, props.Mass()))
    return np.array(out).reshape(-1, 2)


# -- interference -----------------------------------------------------------------------
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


# -- sections ---------------------------------------------------------------------------
def section_edges(shape, origin, normal):
    """Section of ``shape`` by a plane: a list of build123d ``Wire``s (edges chained
    end to end with ``ShapeAnalysis_FreeBounds``)."""
    import build123d as bd

    with kernel("BRepAlgoAPI_Section"):
        pln = gp_Pln(gp_Pnt(*map(float, origin)), gp_Dir(*map(float, normal)))
        op = BRepAlgoAPI_Section(shape, pln, False)
        op.Approximation(False)
        op.ComputePCurveOn1(False)
        op.Build()
        if not op.IsDone():
            raise SurfmodError("obj: OCCT could not section this shape")
        edges = _explore(op.Shape(), TopAbs_EDGE)
        if not edges:
            return []
        seq = TopTools_HSequenceOfShape()
        for e in edges:
            seq.Append(e)
        wires = TopTools_HSequenceOfShape()
        ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(seq, 1e-6, False, wires)
        return [bd.Wire(TopoDS.Wire_s(wires.Value(i))) for i in range(1, wires.Length() + 1)]


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


def wire_edges(wire):
    """The edges of a wire in connection order."""
    out = []
    ex = BRepTools_WireExplorer(TopoDS.Wire_s(getattr(wire, "wrapped", wire)))
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


# -- files ------------------------------------------------------------------------------
def write_brep(shape, path) -> None:
    with kernel("BRepTools.Write_s"):
        if not BRepTools.Write_s(shape, str(path)):
            raise SurfmodError(f"path: could not write BREP {path}")


__all__ = [
    "bounding_box", "closed_solid", "vertex_mean", "common_volume", "edge_deviations", "edge_length", "edge_points",
    "elementary_faces", "gprops", "min_distance", "section_edges",
    "model_tolerance", "planar_faces_on", "sew_solid", "shells_of", "solids_of", "wire_edges", "write_brep",
]
