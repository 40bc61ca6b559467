"""OCCT's side of meshing and display: BRepMesh runs and the triangulations it stores
read back as arrays (with their (u, v) nodes), and the face facts meshing asks of the
kernel (surface handle, UV box, solid, isometric repeats, tolerance).  Measuring and
estimating meshes happen in :mod:`surfmod.meshing`, on the surfaces
:mod:`surfmod.readback` reads.

The same concept as :mod:`surfmod.cli.mesh` at the kernel door (the command meshes with surfmod's own tessellator, checked against this).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from itertools import chain, count

import numpy as np

from ..errors import SurfmodError
from .guard import kernel
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.BinTools import BinTools_ShapeSet
from OCP.Geom2d import Geom2d_Line, Geom2d_TrimmedCurve
from OCP.IMeshData import IMeshData_Failure
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from .geom import surface_type
from .topo import explore, faces_of, wrapped


def clean(shape) -> None:
    """Drop any triangulation stored on ``shape`` so the next BRepMesh starts afresh."""
    with kernel("BRepTools.Clean"):
        BRepTools.Clean_s(wrapped(shape))


def face_basis(face):
    """The face's surface (located) without its ``Geom_RectangularTrimmedSurface``
    wrappers (same parametrization)."""
    with kernel("BRep_Tool.Surface"):
        surf = BRep_Tool.Surface_s(face)
        while surface_type(surf) == "Geom_RectangularTrimmedSurface":
            surf = surf.BasisSurface()
        return surf


def uv_box(face) -> tuple:
    """The face's UV box ``(u0, u1, v0, v1)`` (``BRepTools.UVBounds``)."""
    with kernel("BRepTools.UVBounds"):
        return tuple(float(b) for b in BRepTools.UVBounds_s(face))


def face_solids(shape) -> dict:
    """``{face hash: solid index}`` for the faces of ``shape`` that belong to a solid."""
    owner: dict = {}
    with kernel("TopExp_Explorer"):
        for k, solid in enumerate(explore(wrapped(shape), TopAbs_SOLID)):
            for face in explore(solid, TopAbs_FACE):
                owner.setdefault(face.__hash__(), k)
    return owner


@dataclass
class FaceTriangles:
    """One face's stored BRepMesh triangulation as arrays: ``nodes`` (N, 3) in global
    coordinates (the face's location applied), ``uv`` (N, 2) parameter nodes (NaN where
    not read or absent), ``triangles`` (T, 3) node indices as OCCT stores them (face
    orientation *not* applied; ``reversed`` says whether to flip them for an outward
    normal), ``deflection``, the chordal deflection BRepMesh measured on the face,
    ``instance`` (faces that are located copies of one face share this number, -1 when
    not tracked) and ``rigid`` (the face's location is an isometry)."""

    nodes: np.ndarray
    uv: np.ndarray
    triangles: np.ndarray
    reversed: bool
    deflection: float
    instance: int = -1
    rigid: bool = True


def _coords(getter, n: int, dim: int) -> np.ndarray:
    """``(n, dim)`` coordinates of ``getter(1) ... getter(n)`` (gp_Pnt / gp_Pnt2d): one
    flat ``fromiter`` instead of a list of tuples (a third less time per node)."""
    return np.fromiter(chain.from_iterable(getter(i).Coord() for i in range(1, n + 1)), float, dim * n).reshape(n, dim)


#: Deflection divisors tried on a face BRepMesh left bare: one narrower than the deflection, whose
#: edges' nodes then fall on one line in (u, v) (cone slivers 0.09 wide of an Inventor plate from 0.25 on)
BARE_FINER = (4, 16, 64)
#: Instance-group numbers handed out by :func:`read_triangulation` and :func:`mesh_faces`.
_GROUPS = count()


def _local_triangulation(face):
    """``(nodes in the face's own frame, uv or None, triangles, deflection)`` of one
    face's stored triangulation, read node by node, or ``None``."""
    tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
    if tri is None:
        return None
    n, m = tri.NbNodes(), tri.NbTriangles()
    uv = _coords(tri.UVNode, n, 2) if tri.HasUVNodes() else None
    triangle = tri.Triangle
    idx = np.fromiter(chain.from_iterable(triangle(i).Get() for i in range(1, m + 1)), np.int64, 3 * m).reshape(m, 3) - 1
    return _coords(tri.Node, n, 3), uv, idx, float(tri.Deflection())


def _parse_triangulations(data, version: int) -> list | None:
    """The triangulation table that ``BinTools_ShapeSet::WriteTriangulation`` writes
    (OCCT's binary BRep format: a ``Triangulations N`` line, then per triangulation the
    int32 node and triangle counts, a UV flag byte, from format 4 on a normals flag
    byte, the float64 deflection, the nodes, the UV nodes, the 1-based int32 triangles
    and float32 normals, all little-endian) as ``(nodes, uv or None, triangles,
    deflection)`` tuples, or ``None`` when the bytes do not follow that layout."""
    end = data.find(b"\n")
    words = bytes(data[:end]).split() if end > 0 else []
    if len(words) != 2 or words[0] != b"Triangulations" or not words[1].isdigit():
        return None
    pos, size = end + 1, len(data)
    flags = 2 if version >= 4 else 1
    out = []
    for _ in range(int(words[1])):
        if pos + 16 + flags > size:
            return None
        n, m = (int(x) for x in np.frombuffer(data, "<i4", 2, pos))
        has_uv, has_normals = data[pos + 8], (data[pos + 9] if flags == 2 else 0)
        deflection = float(np.frombuffer(data, "<f8", 1, pos + 8 + flags)[0])
        pos += 16 + flags
        if n < 0 or m < 0 or pos + n * (24 + 16 * bool(has_uv) + 12 * bool(has_normals)) + 12 * m > size:
            return None
        # copies: aligned, writable arrays that do not keep the whole dump alive
        nodes = np.frombuffer(data, "<f8", 3 * n, pos).reshape(n, 3).copy()
        pos += 24 * n
        uv = None
        if has_uv:
            uv = np.frombuffer(data, "<f8", 2 * n, pos).reshape(n, 2).copy()
            pos += 16 * n
        triangles = np.frombuffer(data, "<i4", 3 * m, pos).reshape(m, 3).astype(np.int64) - 1
        pos += 12 * m + 12 * n * bool(has_normals)
        out.append((nodes, uv, triangles, deflection))
    return out if pos == size else None


def _triangulation_table(faces: list) -> list | None:
    """Every face's stored triangulation as :func:`_local_triangulation` gives it, read
    for all faces at once: OCCT serializes the triangulations into one binary buffer
    (``BinTools_ShapeSet``) that NumPy reads at memory speed, where reading node by node
    costs a Python call per node.  Located instances of one face share one entry
    (the same tuple object).  ``None`` when the buffer cannot be matched to the faces
    (an unexpected layout, or two faces sharing one triangulation object)."""
    table = BinTools_ShapeSet()
    table.SetWithTriangles(True)
    buckets: dict = {}  # hash of the unlocated face -> [(unlocated face, slot)]
    slots = []
    n_slots = 0
    for face in faces:
        if BRep_Tool.Triangulation_s(face, TopLoc_Location()) is None:
            slots.append(-1)
            continue
        bare = face.Located(TopLoc_Location())
        bucket = buckets.setdefault(bare.__hash__(), [])
        slot = next((s for other, s in bucket if other.IsSame(bare)), -1)
        if slot < 0:
            slot, n_slots = n_slots, n_slots + 1
            bucket.append((bare, slot))
            table.AddShape(bare)  # this face's geometry and triangulation, not its edges
        slots.append(slot)
    buffer = io.BytesIO()
    table.WriteTriangulation(buffer)
    parsed = _parse_triangulations(buffer.getvalue(), table.FormatNb())
    if parsed is None or len(parsed) != n_slots:
        return None
    return [parsed[s] if s >= 0 else None for s in slots]


def _face_triangles(face, got, with_uv: bool, with_nodes: bool, group: int) -> FaceTriangles | None:
    """:class:`FaceTriangles` of ``face`` from its local triangulation ``got``."""
    if got is None or len(got[2]) == 0:
        return None
    nodes, uv, idx, deflection = got
    n = len(nodes)
    uv = uv if with_uv and uv is not None else np.full((n, 2), np.nan)
    rigid = True
    loc = face.Location()
    if not with_nodes:
        nodes = np.full((n, 3), np.nan)
    elif not loc.IsIdentity():
        t = loc.Transformation()
        rot = np.array([[t.Value(i, j) for j in range(1, 4)] for i in range(1, 4)])
        nodes = nodes @ rot.T + np.array([t.Value(i, 4) for i in range(1, 4)])
        rigid = abs(abs(t.ScaleFactor()) - 1.0) < 1e-12
    return FaceTriangles(nodes, uv, idx, face.Orientation() == TopAbs_REVERSED, deflection, group, rigid)


def read_triangulation(face, with_uv: bool, with_nodes: bool = True) -> FaceTriangles | None:
    """One face's stored triangulation as :class:`FaceTriangles`, or ``None`` when it has
    none (:func:`mesh_faces` reads all faces of a shape at once)."""
    return _face_triangles(face, _local_triangulation(face), with_uv, with_nodes, next(_GROUPS))


def bound_cone_seams(faces) -> None:
    """Trim cone seams' line p-curves leaning off the v direction to the edge's range, in place (same values):
    BRepMesh's seam refinement tells the two apart at ``FirstParameter()``, -1e100 for a line, and swaps them."""
    for face in (TopoDS.Face(f.Oriented(TopAbs_FORWARD)) for f in faces):
        edges = explore(face, TopAbs_EDGE) if surface_type(face_basis(face)) == "Geom_ConicalSurface" else []
        for edge in (TopoDS.Edge(e.Oriented(TopAbs_FORWARD)) for e in edges):
            sides = [BRep_Tool.CurveOnSurface_s(e, face, 0.0, 0.0) for e in (edge, TopoDS.Edge(edge.Reversed()))]
            leaning = any(isinstance(c, Geom2d_Line) and c.Lin2d().Direction().X() != 0.0 for c in sides)
            if leaning and BRep_Tool.IsClosed_s(edge, face):
                pair = (Geom2d_TrimmedCurve(c, *BRep_Tool.Range_s(edge, face)) for c in sides)
                BRep_Builder().UpdateEdge(edge, *pair, face, BRep_Tool.Tolerance_s(edge))


def mesh_faces(shape, deflection: float, angular: float = 0.5, *, relative: bool = False, parallel: bool = False,
               with_uv=True, with_nodes: bool = True) -> list[tuple]:
    """The one BRepMesh call of surfmod: clear any stored triangulation, run
    ``BRepMesh_IncrementalMesh(shape, deflection, relative, angular, parallel)`` and read
    every face's triangulation back (after :func:`bound_cone_seams`; faces it left bare
    meshed alone first, finer, see :data:`BARE_FINER`).

    Returns ``[(index, face, FaceTriangles or None)]`` per face in exploration order
    (``None``: BRepMesh left the face without triangles).  ``with_uv`` is a bool or a
    predicate ``with_uv(face) -> bool`` choosing the faces whose (u, v) nodes are kept;
    ``with_nodes=False`` leaves the 3-D nodes NaN.  Located instances of one face
    (assemblies) are read once and share ``FaceTriangles.instance``.

    >>> import build123d as bd
    >>> [(k, len(t.triangles)) for k, _, t in mesh_faces(bd.Box(1, 1, 1), 0.1)][:2]
    [(0, 2), (1, 2)]
    """
    shp = wrapped(shape)
    if shp is None:
        raise SurfmodError(f"shape: expected a build123d shape or TopoDS_Shape, got {type(shape).__name__}")
    clean(shp)
    with kernel("BRepMesh_IncrementalMesh"):
        faces = list(faces_of(shp))
        bound_cone_seams(faces)
        done = BRepMesh_IncrementalMesh(shp, float(deflection), bool(relative), float(angular), bool(parallel))
        bare = [f for f in faces if BRep_Tool.Triangulation_s(f, TopLoc_Location()) is None]
        # narrower than the deflection (see BARE_FINER): meshed alone first, their edges then shared; not
        # where BRepMesh found a wire crossing itself or open (PL1045A: alone it meshes a face 136 off)
        if bare and done.GetStatusFlags() == int(IMeshData_Failure):
            clean(shp)
            for face, finer in ((f, k) for f in bare for k in BARE_FINER):
                if BRep_Tool.Triangulation_s(face, TopLoc_Location()) is None:
                    BRepMesh_IncrementalMesh(face, deflection / finer, bool(relative), float(angular), bool(parallel))
            BRepMesh_IncrementalMesh(shp, float(deflection), bool(relative), float(angular), bool(parallel))
        table = _triangulation_table(faces)
        if table is None:  # read face by face, sharing nothing
            table = [_local_triangulation(face) for face in faces]
        groups: dict = {}  # id of a shared entry -> its instance group
        out = []
        for k, (face, got) in enumerate(zip(faces, table)):
            group = groups.setdefault(id(got), next(_GROUPS)) if got is not None else -1
            keep_uv = with_uv(face) if callable(with_uv) else bool(with_uv)
            out.append((k, face, _face_triangles(face, got, keep_uv, with_nodes, group)))
        return out


def face_uv_triangles(face, deflection: float, angular: float = 0.1):
    """UV nodes ``(M, 2)`` and triangles ``(T, 3)`` of a BRepMesh triangulation of one
    face (the face's trimmed parameter region as a polygonal patchwork)."""
    ((_, _, got),) = mesh_faces(face, deflection, angular, parallel=True, with_nodes=False)
    if got is None or np.isnan(got.uv).any():
        raise SurfmodError("obj: OCCT could not triangulate a trimmed face's parameter region")
    return got.uv, got.triangles


def face_instances(shape) -> list[tuple]:
    """``[(face, first)]`` per face of ``shape`` in exploration order: ``first`` is the
    position of an earlier face this one repeats at an isometric location (the same face
    moved rigidly, as in assemblies), else -1."""
    out = []
    seen: dict = {}  # hash of the unlocated face -> [(unlocated face, its first position)]
    with kernel("TopoDS_Face locations"):
        for k, face in enumerate(faces_of(wrapped(shape))):
            loc = face.Location()
            rigid = loc.IsIdentity() or abs(abs(loc.Transformation().ScaleFactor()) - 1.0) < 1e-12
            bare = face.Located(TopLoc_Location())
            bucket = seen.setdefault(bare.__hash__(), [])
            first = next((at for other, at in bucket if other.IsSame(bare)), -1) if rigid else -1
            if rigid and first < 0:
                bucket.append((bare, k))
            out.append((face, first))
    return out


def max_tolerance(shape) -> float:
    """Largest vertex/edge/face tolerance stored in a shape (how far OCCT allows its
    topology to stray from the geometry)."""
    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(wrapped(shape), 1))
