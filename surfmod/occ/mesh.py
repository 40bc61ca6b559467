"""OCCT's side of meshing and display: BRepMesh triangulations with their (u, v) nodes,
per-face surfaces for measuring chordal deviation, iso-curves (``UIso``/``VIso``) and
the figures needed to estimate a triangle count before meshing.

The plain Python loops here run over OCCT calls (one per node or per sample); they are
the kernel boundary and the measurement side, not a NumPy evaluation path.

The same concept as :mod:`surfmod.cli.mesh` at the kernel door (the command meshes with surfmod's own tessellator, checked against this).
"""

from __future__ import annotations

import io
import math
import statistics
from dataclasses import dataclass
from itertools import chain, count

import numpy as np

from ..errors import SurfmodError
from .guard import kernel
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.BinTools import BinTools_ShapeSet
from OCP.Bnd import Bnd_Box
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.gp import gp_Pnt, gp_Vec
from .arrays import pnts_to_numpy_1d, to_numpy_1d
from .geom import read_bezier_surface, read_bspline_curve, read_bspline_surface, surface_type
from .topo import faces_of, wrapped
from .bindings import box_limits, TColgp_Array1OfPnt, TColStd_Array1OfReal


@dataclass
class FaceMesh:
    """One face's BRepMesh triangulation: 3-D ``nodes`` (global coordinates), ``uv``
    nodes on the face's surface, ``triangles`` oriented outwards (face orientation
    applied), the face's ``surface`` (global coordinates, trimmed-surface wrappers
    removed), its ``face``, ``bounds`` (UV box: given, or read on first use; closed-form
    measurement never needs it), ``index`` in exploration order and ``solid`` (index of
    the solid it belongs to, -1 for faces outside any solid) and ``repeats``: the
    position in the same list of an earlier face this one repeats at an isometric
    location (same triangulation, same surface moved rigidly: the same deviations), or
    -1."""

    nodes: np.ndarray
    uv: np.ndarray
    triangles: np.ndarray
    surface: object
    face: object
    uv_box: tuple | None
    index: int = 0
    solid: int = -1
    repeats: int = -1

    @property
    def bounds(self) -> tuple:
        """The face's UV box ``(u0, u1, v0, v1)`` (``BRepTools.UVBounds``)."""
        if self.uv_box is None:
            with kernel("BRepTools.UVBounds"):
                self.uv_box = tuple(float(b) for b in BRepTools.UVBounds_s(self.face))
        return self.uv_box


def clean(shape) -> None:
    """Drop any triangulation stored on ``shape`` so the next BRepMesh starts afresh."""
    with kernel("BRepTools.Clean"):
        BRepTools.Clean_s(wrapped(shape))


def basis_surface(surf):
    """The surface under ``Geom_RectangularTrimmedSurface`` wrappers (same parametrization)."""
    while surface_type(surf) == "Geom_RectangularTrimmedSurface":
        surf = surf.BasisSurface()
    return surf


def _face_solids(shp) -> dict:
    """``{face hash: solid index}`` for the faces that belong to a solid."""
    owner = {}
    solids = TopExp_Explorer(shp, TopAbs_SOLID)
    k = 0
    while solids.More():
        faces = TopExp_Explorer(solids.Current(), TopAbs_FACE)
        while faces.More():
            owner.setdefault(faces.Current().__hash__(), k)
            faces.Next()
        k += 1
        solids.Next()
    return owner


#: Surfaces whose distance has a closed form (:func:`elementary_parameters`): their (u, v)
#: nodes are not needed to measure a mesh.
ANALYTIC = ("Geom_Plane", "Geom_CylindricalSurface", "Geom_ConicalSurface", "Geom_SphericalSurface",
            "Geom_ToroidalSurface")


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


def mesh_faces(shape, deflection: float, angular: float = 0.5, *, relative: bool = False, parallel: bool = False,
               with_uv=True, with_nodes: bool = True) -> list[tuple]:
    """The one BRepMesh call of surfmod: clear any stored triangulation, run
    ``BRepMesh_IncrementalMesh(shape, deflection, relative, angular, parallel)`` and read
    every face's triangulation back.

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
        BRepMesh_IncrementalMesh(shp, float(deflection), bool(relative), float(angular), bool(parallel))
        faces = list(faces_of(shp))
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
    uv, idx = got.uv, got.triangles
    return uv, idx


def brepmesh(shape, deflection: float, angular: float = 0.5, *, relative: bool = False, missing: list | None = None,
             uv_bounds: dict | None = None) -> list[FaceMesh]:
    """Run ``BRepMesh_IncrementalMesh`` (after clearing old triangulations) and return the
    per-face triangulations.  BRepMesh discretizes each edge once, so nodes of faces that
    share an edge coincide bit for bit.  Faces BRepMesh left without triangles are
    skipped; their indices are appended to ``missing`` when a list is given.
    ``uv_bounds``: faces' UV boxes already known (by face hash, from :func:`shape_figures`)."""
    shp = wrapped(shape)
    surfaces = {}

    def needs_uv(face):
        # analytic faces are measured in closed form, without their (u, v) nodes
        surfaces[face.__hash__()] = surf = basis_surface(BRep_Tool.Surface_s(face))
        return surface_type(surf) not in ANALYTIC

    out = []
    first: dict = {}  # instance group -> position in out of its first rigid face
    meshed = mesh_faces(shp, deflection, angular, relative=relative, with_uv=needs_uv)
    with kernel("BRepMesh triangulations"):
        owner = _face_solids(shp)
        for k, face, got in meshed:
            if got is None:
                if missing is not None:
                    missing.append(k)
                continue
            tri = got.triangles[:, ::-1] if got.reversed else got.triangles
            known = uv_bounds.get(face.__hash__()) if uv_bounds is not None else None
            bounds = None if known is None else tuple(float(b) for b in known)  # else read when needed
            shared = got.rigid and got.instance >= 0
            repeats = first.get(got.instance, -1) if shared else -1
            if shared and got.instance not in first:
                first[got.instance] = len(out)
            out.append(FaceMesh(got.nodes, got.uv, tri, surfaces[face.__hash__()], face, bounds, k,
                                owner.get(face.__hash__(), -1), repeats))
    if not out:
        raise SurfmodError("shape: has no faces to triangulate")
    return out


def surface_info(surf) -> dict:
    """What measuring against a face's surface needs: its OCCT type ``name``, the
    NumPy-readable ``bspline`` data (B-spline/Bezier surfaces, ``None`` otherwise) and
    per direction whether it is ``periodic`` with its ``period`` and parameter
    ``range``."""
    name = surface_type(surf)
    with kernel(f"{name} parameters"):
        u0, u1, v0, v1 = surf.Bounds()
        info = {
            "name": name,
            "periodic": (bool(surf.IsUPeriodic()), bool(surf.IsVPeriodic())),
            "period": (surf.UPeriod() if surf.IsUPeriodic() else 0.0, surf.VPeriod() if surf.IsVPeriodic() else 0.0),
            "range": ((u0, u1), (v0, v1)),
            "bspline": None,
            "bezier": None,
        }
    if name == "Geom_BSplineSurface":
        info["bspline"] = read_bspline_surface(surf)
    elif name == "Geom_BezierSurface":
        info["bezier"] = read_bezier_surface(surf)
    return info


def curve_info(curve) -> dict:
    """A ``Geom_Curve`` as data NumPy can evaluate in OCCT's parametrization:
    ``{"name", "bspline"|"bezier" (reader dicts), "line": (origin, direction),
    "conic": (centre, x axis, y axis, a, b) for circles and ellipses}``; trimmed-curve
    wrappers are removed (same parametrization).  Other types give only ``name``."""
    name = curve.DynamicType().Name()
    with kernel(f"{name} parameters"):
        while name == "Geom_TrimmedCurve":
            curve = curve.BasisCurve()
            name = curve.DynamicType().Name()
        info = {"name": name}
        if name == "Geom_BSplineCurve":
            info["bspline"] = read_bspline_curve(curve)
        elif name == "Geom_BezierCurve":
            poles = TColgp_Array1OfPnt(1, curve.NbPoles())
            curve.Poles(poles)
            weights = None
            if curve.IsRational():
                w = TColStd_Array1OfReal(1, curve.NbPoles())
                curve.Weights(w)
                weights = to_numpy_1d(w)
            info["bezier"] = {"points": pnts_to_numpy_1d(poles), "weights": weights}
        elif name == "Geom_Line":
            ax = curve.Position()
            info["line"] = (np.array(ax.Location().Coord()), np.array(ax.Direction().Coord()))
        elif name in ("Geom_Circle", "Geom_Ellipse"):
            ax = curve.Position()
            a = curve.Radius() if name == "Geom_Circle" else curve.MajorRadius()
            b = curve.Radius() if name == "Geom_Circle" else curve.MinorRadius()
            info["conic"] = (np.array(ax.Location().Coord()), np.array(ax.XDirection().Coord()),
                             np.array(ax.YDirection().Coord()), a, b)
    return info


def swept_info(surf) -> dict | None:
    """Axis/direction and basis curve of a surface of revolution (``"axis": (origin,
    direction)``) or of linear extrusion (``"direction"``); ``None`` for other types."""
    name = surface_type(surf)
    if name not in ("Geom_SurfaceOfRevolution", "Geom_SurfaceOfLinearExtrusion"):
        return None
    with kernel(f"{name} parameters"):
        out = {"name": name, "curve": curve_info(surf.BasisCurve())}
        if name == "Geom_SurfaceOfRevolution":
            ax = surf.Axis()
            out["axis"] = (np.array(ax.Location().Coord()), np.array(ax.Direction().Coord()))
        else:
            out["direction"] = np.array(surf.Direction().Coord())
    return out


def surface_d1(surf, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(N, 2, 2, 3)`` position and first partials of a ``Geom_Surface`` from ``D1``
    (entry ``[1, 1]`` is left zero)."""
    out = np.zeros((len(u), 2, 2, 3))
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    with kernel("Geom_Surface.D1"):
        for a, (uu, vv) in enumerate(zip(u, v)):
            surf.D1(float(uu), float(vv), p, du, dv)
            out[a, 0, 0] = (p.X(), p.Y(), p.Z())
            out[a, 1, 0] = (du.X(), du.Y(), du.Z())
            out[a, 0, 1] = (dv.X(), dv.Y(), dv.Z())
    return out


def elementary_parameters(surf) -> tuple | None:
    """``(type name, origin, axis, sizes)`` of a plane, sphere, cylinder, cone or torus:
    its placement's location and direction and ``(0, 0)``, ``(radius, 0)``, ``(radius,
    0)``, ``(reference radius, semi-angle)`` or ``(major, minor radius)``; ``None`` for
    any other surface type (:func:`surfmod.meshing.analytic_distance.parameters` turns these
    into closed-form distances)."""
    name = surface_type(surf)
    if name not in ANALYTIC:
        return None
    with kernel(f"{name} parameters"):
        ax = surf.Position()
        frame = ax.Location().Coord(), ax.Direction().Coord()
        if name == "Geom_Plane":
            sizes = (0.0, 0.0)
        elif name in ("Geom_SphericalSurface", "Geom_CylindricalSurface"):
            sizes = (surf.Radius(), 0.0)
        elif name == "Geom_ConicalSurface":
            sizes = (surf.RefRadius(), surf.SemiAngle())
        else:
            sizes = (surf.MajorRadius(), surf.MinorRadius())
    return name, *frame, sizes


def iso_curve(surf, direction: int, value: float):
    """OCCT's exact iso-parametric curve: ``UIso(value)`` (direction 0: u fixed, a curve
    in v) or ``VIso(value)`` (direction 1)."""
    with kernel("Geom_Surface.UIso/VIso"):
        return surf.UIso(float(value)) if direction == 0 else surf.VIso(float(value))


def curve_points(curve, t: np.ndarray) -> np.ndarray:
    """``(N, 3)`` points of a ``Geom_Curve`` (``Value`` per parameter)."""
    with kernel("Geom_Curve.Value"):
        out = np.empty((len(t), 3))
        for a, tt in enumerate(t):
            p = curve.Value(float(tt))
            out[a] = (p.X(), p.Y(), p.Z())
        return out


def shape_figures(shape, samples: int = 5, sample_face=None, uv_bounds: dict | None = None):
    """Per curved face ``(area, median sqrt(|k1| |k2|) with each |k| floored by 1/diagonal)``
    from a ``samples`` x ``samples`` grid over the face's UV box (area of the box's patch:
    at least the face's), and the bounding-box diagonal: enough to estimate how many
    triangles a chordal tolerance needs before asking BRepMesh for them.  Planes need
    no figure (a plane's triangle count does not grow as the tolerance shrinks), and a
    face that repeats an earlier one at an isometric location (assemblies) repeats its
    figure without being sampled again.

    ``sample_face(face, surface, (u0, u1, v0, v1), samples, floor)``, when given, is asked
    first for each curved face and returns its figure (any pair, e.g. a list the caller
    fills in after this returns, to sample all its faces at once), or ``None`` to leave
    the face to ``GeomLProp`` here.  ``uv_bounds``, a dict, receives each sampled face's
    ``BRepTools.UVBounds`` by face hash (for :func:`brepmesh`)."""
    shp = wrapped(shape)
    with kernel("shape figures (Bnd_Box, GeomLProp)"):
        box = Bnd_Box()
        BRepBndLib.Add_s(shp, box)
        if box.IsVoid():
            raise SurfmodError("shape: is empty")
        x0, y0, z0, x1, y1, z1 = box_limits(box)
        diag = float(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))
        floor = 1.0 / max(diag, 1e-300)
        figures = []
        seen: dict = {}  # hash of the unlocated face -> [(unlocated face, its figure)]
        for face in faces_of(shp):
            loc = face.Location()
            rigid = loc.IsIdentity() or abs(abs(loc.Transformation().ScaleFactor()) - 1.0) < 1e-12
            bare = face.Located(TopLoc_Location())
            bucket = seen.setdefault(bare.__hash__(), [])
            known = next((f for other, f in bucket if other.IsSame(bare)), None) if rigid else None
            if known is None:
                known = _face_figure(face, samples, floor, sample_face, uv_bounds)
                if rigid:
                    bucket.append((bare, known))
            if known is not False:  # False: a plane
                figures.append(known)
    return figures, diag


def _face_figure(face, samples: int, floor: float, sample_face, uv_bounds: dict | None = None):
    """:func:`shape_figures`' figure of one face, or ``False`` for a plane."""
    surf = basis_surface(BRep_Tool.Surface_s(face))
    name = surface_type(surf)
    if name == "Geom_Plane":
        return False
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    if uv_bounds is not None:
        uv_bounds[face.__hash__()] = (u0, u1, v0, v1)
    figure = sample_face(face, surf, (u0, u1, v0, v1), samples, floor) if sample_face is not None else None
    if figure is not None:
        return figure
    if name in ("Geom_CylindricalSurface", "Geom_SphericalSurface"):
        # closed forms of what the sampled figures below come to (|Su x Sv|, k1, k2)
        r = surf.Radius()
        if name == "Geom_CylindricalSurface":
            return r * (u1 - u0) * (v1 - v0), float(np.sqrt(max(1 / r, floor) * floor))
        return (r * r * (u1 - u0) * float(np.mean(np.cos(np.linspace(v0, v1, samples)))) * (v1 - v0),
                max(1 / r, floor))
    if name in ("Geom_ConicalSurface", "Geom_ToroidalSurface"):
        # the same for surfaces of revolution whose figures vary along v only: the
        # circle's radius rho(v) gives |Su x Sv| and the parallel's curvature
        # (five samples: plain floats cost less than NumPy's per-call overhead)
        vs = [v0 + (v1 - v0) * k / (samples - 1) for k in range(samples)]
        if name == "Geom_ConicalSurface":
            a, r0 = surf.SemiAngle(), surf.RefRadius()
            sa, ca = math.sin(a), math.cos(a)
            rows = [(r0 + v * sa, 1.0, ca) for v in vs]  # (rho, |Su x Sv| / |rho|, cos of the normal's tilt)
            k_meridian = 0.0
        else:
            big, r = surf.MajorRadius(), surf.MinorRadius()
            rows = [(big + r * math.cos(v), r, math.cos(v)) for v in vs]
            k_meridian = 1.0 / r
        # GeomLProp: no curvature at the apex / on the axis (rho = 0)
        vals = [math.sqrt(max(k_meridian, floor) * max(abs(c / rho), floor)) for rho, _, c in rows if rho != 0]
        area = sum(f * abs(rho) for rho, f, _ in rows) / samples * (u1 - u0) * (v1 - v0)
        return area, statistics.median(vals) if vals else floor
    lp = GeomLProp_SLProps(surf, 2, 1e-9)
    vals, jac = [], []
    # elementary surfaces are curved alike along u: three columns tell them
    ns = min(samples, 3) if name in ANALYTIC else samples
    for uu in np.linspace(u0, u1, ns):
        for vv in np.linspace(v0, v1, samples):
            lp.SetParameters(float(uu), float(vv))
            jac.append(lp.D1U().Crossed(lp.D1V()).Magnitude())
            if lp.IsCurvatureDefined():
                k1, k2 = abs(lp.MaxCurvature()), abs(lp.MinCurvature())
                vals.append(np.sqrt(max(k1, floor) * max(k2, floor)))
    area = float(np.mean(jac)) * (u1 - u0) * (v1 - v0)
    return area, float(np.median(vals)) if vals else floor


def max_tolerance(shape) -> float:
    """Largest vertex/edge/face tolerance stored in a shape (how far OCCT allows its
    topology to stray from the geometry)."""
    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(wrapped(shape), 1))
