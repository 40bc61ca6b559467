"""An exact gouge check of G-code, independent of surfmod's own check.

surfmod verifies its moves against a fine triangulation with sampled drop-cutter heights.
This module judges the written G-code with OCCT's exact B-rep distance instead:

* ball end + shank of radius ``r``: the tool is the set of points within ``r`` of the
  segment from the ball centre up the axis, so the volume it sweeps along a run of moves in
  one vertical plane is exactly the set of points within ``r`` of the planar "ribbon" under
  the tip polyline lifted by ``r`` and extended straight up.  A move cuts deeper than ``d``
  into the part exactly when ``BRepExtrema_DistShapeShape(ribbon, part) < r - d``.
* flat end + shank: the cylinder shrunk by ``d`` (radius ``r - d``, bottom ``d`` higher)
  is placed at points along each move, at most ``r / 20`` apart and closely enough that the
  tip height changes by at most ``d / 4`` between them; it must not meet the part.
"""

from __future__ import annotations

import re

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BndLib import BndLib_AddSurface
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
from OCP.BRepTools import BRepTools
from OCP.Extrema import Extrema_ExtFlag_MIN
from OCP.GeomAbs import GeomAbs_Plane
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_VERTEX
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound

from surfmod.occ.bindings import box_limits


def material(shape):
    """The faces of ``shape`` as one compound: free edges and vertices of a STEP file
    (construction wires) are not material a tool can cut."""
    shape = getattr(shape, "wrapped", shape)
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        builder.Add(compound, explorer.Current())
        explorer.Next()
    return compound


WORD = re.compile(r"([XYZ])(-?\d+(?:\.\d*)?)")


def gcode_positions(text: str) -> np.ndarray:
    """Tool-tip positions (N, 3) after every motion line (G0/G1), modal coordinates."""
    pos = [np.nan, np.nan, np.nan]
    out = []
    for line in text.splitlines():
        if not line.startswith(("G0", "G1")):
            continue
        for axis, value in WORD.findall(line):
            pos["XYZ".index(axis)] = float(value)
        if not np.isnan(pos).any():
            out.append(list(pos))
    return np.array(out)


def _planar_runs(points: np.ndarray):
    """Split a polyline into runs whose (x, y) advance monotonically along one line."""
    runs, start = [], 0
    direction = None
    for i in range(1, len(points)):
        d = points[i, :2] - points[i - 1, :2]
        n = np.linalg.norm(d)
        if n < 1e-12:
            continue
        d /= n
        if direction is None:
            direction = d
            continue
        if d @ direction < 1 - 1e-9:
            runs.append(points[start:i])
            start, direction = i - 1, d
    runs.append(points[start:])
    return runs


def ball_clearance(part, points: np.ndarray, radius: float, top: float) -> float:
    """Smallest distance from the part to the ribbons swept by the ball centre and its
    axis up to height ``top``, capped at ``radius``; the deepest cut of the path is
    ``radius`` minus it.  Each ribbon is measured against the faces with a box of
    :func:`face_cells` within ``radius`` of its own: a face farther away cuts nothing, and
    the distance to the others is the distance to the whole part wherever it is below
    ``radius``."""
    faces, boxes = face_cells(getattr(part, "wrapped", part))
    best = radius
    for run in _planar_runs(points):
        keep = np.r_[True, np.any(np.abs(np.diff(run, axis=0)) > 0, axis=1)]
        run = run[keep]
        if len(run) < 2:
            continue
        best = min(best, *(_ribbon_clearance(faces, boxes, run[k:k + RIBBON + 1], radius, top)
                           for k in range(0, len(run) - 1, RIBBON)))
    return best


#: points per ribbon piece: the pieces of a ribbon share their ends, so together they are
#: the ribbon, and a short piece meets few faces' boxes (OCCT measures it against those)
RIBBON = 32


def _ribbon_clearance(faces, boxes, run, radius, top):
    """The distance from the faces near it to the ribbon of one piece of a run (capped at
    ``radius``).  A piece may start or end on a vertical move (a step up a wall): there the
    ribbon's side would run back over that move, so the polygon starts after the first
    stack of positions at one (x, y) and ends before the last one, and each stack is its
    own vertical edge from its lowest centre up to ``top``."""
    centre = run + [0.0, 0.0, radius]
    near = _near_strips(boxes, centre, top, radius)
    if not len(near):
        return radius
    moved = np.linalg.norm(np.diff(centre[:, :2], axis=0), axis=1) > 1e-12
    if not moved.any():
        ribbon = [_riser(centre, top)]
    else:
        first, last = int(np.argmax(moved)), len(moved) - int(np.argmax(moved[::-1]))
        polygon = BRepBuilderAPI_MakePolygon()
        for x, y, z in centre[first:last + 1]:
            polygon.Add(gp_Pnt(float(x), float(y), float(z)))
        polygon.Add(gp_Pnt(float(centre[last, 0]), float(centre[last, 1]), top))
        polygon.Add(gp_Pnt(float(centre[first, 0]), float(centre[first, 1]), top))
        polygon.Close()
        ribbon = [BRepBuilderAPI_MakeFace(polygon.Wire(), True).Face()]
        ribbon += [_riser(stack, top) for stack in (centre[:first + 1], centre[last:]) if len(stack) > 1]
    dist = BRepExtrema_DistShapeShape(compound(ribbon), compound(faces[k] for k in near), Extrema_ExtFlag_MIN)
    assert dist.IsDone()
    return min(dist.Value(), radius)


def _riser(stack, top):
    """The vertical edge swept by the axis above a stack of centres at one (x, y)."""
    x, y, z = stack[np.argmin(stack[:, 2])]
    return BRepBuilderAPI_MakeEdge(gp_Pnt(float(x), float(y), float(z)), gp_Pnt(float(x), float(y), top)).Edge()


def flat_cuts(part, points: np.ndarray, radius: float, depth: float, top: float, moves=None) -> list[int]:
    """Indices of moves (of ``moves``, by default every one) where the flat end, shrunk by
    ``depth``, meets the part.  Each cylinder is measured against the faces with a box of
    :func:`face_cells` meeting it (the same distance as against the whole part, found
    faster); a placement no such box meets is clear without asking OCCT, and so is one
    nearer than ``D`` to the last placement measured, ``D`` from the part (from those
    faces by OCCT, from the others by their cells' boxes): the cylinder there lies within
    that one moved by less than ``D`` and, placed lower, a slab at its top that no box
    meets, so no point of it comes within 0 of the part."""
    faces, boxes = face_cells(getattr(part, "wrapped", part))
    rho = radius - depth
    bad, last, clear = [], None, 0.0
    for i in range(len(points) - 1) if moves is None else moves:
        a, b = points[i], points[i + 1]
        n = int(max(np.ceil(np.linalg.norm(b[:2] - a[:2]) / (radius / 20)),
                    np.ceil(abs(b[2] - a[2]) / (depth / 4)) if np.linalg.norm(b[:2] - a[:2]) > 0 else 0, 1))
        lo = np.r_[np.minimum(a, b)[:2] - rho, min(a[2], b[2]) + depth]
        hi = np.r_[np.maximum(a, b)[:2] + rho, top]
        near = _near(boxes, lo, hi)
        if not len(near):
            continue
        boxes_near = boxes[near]
        for t in np.linspace(0.0, 1.0, n + 1):
            p = a + t * (b - a)
            if last is not None and np.linalg.norm(p - last) < clear - 1e-9 and (
                    p[2] >= last[2] or not len(_near_cylinder(boxes, p[:2], rho, top + p[2] - last[2], top))):
                continue
            here = near[_near_cylinder(boxes_near, p[:2], rho, p[2] + depth, top)]
            if not len(here):
                continue
            axis = gp_Ax2(gp_Pnt(float(p[0]), float(p[1]), float(p[2] + depth)), gp_Dir(0, 0, 1))
            cutter = BRepPrimAPI_MakeCylinder(axis, rho, top - p[2] - depth).Shape()
            dist = BRepExtrema_DistShapeShape(cutter, compound(faces[k] for k in here), Extrema_ExtFlag_MIN)
            assert dist.IsDone()
            if dist.Value() <= 1e-9:
                bad.append(i)
                break
            # the faces left out are at least their cells' boxes' distance away
            others = np.ones(len(faces), bool)
            others[here] = False
            last = p
            clear = min(dist.Value(), _cylinder_gap(boxes[others], p[:2], rho, p[2] + depth, top).min(initial=np.inf))
    return bad


def _near_strips(boxes: np.ndarray, centre: np.ndarray, top: float, radius: float) -> np.ndarray:
    """Indices of the faces whose boxes ``(F, 2, 3)`` come nearer than ``radius`` to the
    ribbon over the polyline ``centre`` up to ``top``: the ribbon lies in the union of the
    boxes of its strips (a segment and the wall above it), and a face's box is no nearer
    to it than the least Euclidean distance between the face's box and a strip's box
    (on Ventilator 10 % fewer faces than the piece's box grown by ``radius``)."""
    lo = np.minimum(centre[:-1], centre[1:])
    hi = np.maximum(centre[:-1], centre[1:])
    hi[:, 2] = np.maximum(hi[:, 2], top)
    # the faces whose whole box is near first, then their cells
    whole = np.stack([boxes[:, :, 0].min(1), boxes[:, :, 1].max(1)], axis=1)
    near = np.flatnonzero(_gap(whole[:, None], lo, hi).min(1) < radius)
    return near[_gap(boxes[near, :, None], lo, hi).min((1, 2)) < radius]


def _cylinder_gap(boxes: np.ndarray, centre, rho: float, bottom: float, top: float) -> np.ndarray:
    """Distances ``(F, K)`` from the boxes ``(F, K, 2, 3)`` to the upright cylinder of
    radius ``rho`` around ``centre`` (x, y) from ``bottom`` to ``top``: the (x, y)
    rectangle's distance beyond ``rho`` from the axis, and the z ranges' gap."""
    gap = np.maximum(0.0, np.maximum(boxes[:, :, 0, :2] - centre, centre - boxes[:, :, 1, :2]))
    side = np.maximum(np.hypot(gap[..., 0], gap[..., 1]) - rho, 0.0)
    up = np.maximum(0.0, np.maximum(boxes[:, :, 0, 2] - top, bottom - boxes[:, :, 1, 2]))
    return np.hypot(side, up)


def _near_cylinder(boxes: np.ndarray, centre, rho: float, bottom: float, top: float) -> np.ndarray:
    """Indices of the faces with a box of ``(F, K, 2, 3)`` meeting that cylinder."""
    return np.flatnonzero((_cylinder_gap(boxes, centre, rho, bottom, top) <= 0).any(axis=1))


def _gap(boxes: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Least distances between boxes ``(..., 2, 3)`` and the boxes ``lo``-``hi`` ``(S, 3)``
    (broadcast as ``boxes[..., 0, :]`` against ``lo``)."""
    gap = np.maximum(0.0, np.maximum(lo - boxes[..., 1, :], boxes[..., 0, :] - hi))
    return np.sqrt((gap * gap).sum(-1))


def _near(boxes: np.ndarray, lo, hi) -> np.ndarray:
    """Indices of the faces with a box of ``(F, K, 2, 3)`` meeting the box ``lo``-``hi``."""
    return np.flatnonzero(np.any(np.all((boxes[:, :, 0] <= hi) & (boxes[:, :, 1] >= lo), axis=2), axis=1))


def compound(shapes):

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for s in shapes:
        builder.Add(compound, s)
    return compound


def face_boxes(part):
    """The faces of ``part`` and their OCCT bounding boxes ``(F, 2, 3)``."""
    faces, boxes = [], []
    explorer = TopExp_Explorer(part, TopAbs_FACE)
    while explorer.More():
        face = explorer.Current()
        box = Bnd_Box()
        BRepBndLib.Add_s(face, box, False)  # from the geometry, not a stored triangulation
        x0, y0, z0, x1, y1, z1 = box_limits(box)
        faces.append(face)
        boxes.append([[x0, y0, z0], [x1, y1, z1]])
        explorer.Next()
    return faces, np.array(boxes)


#: each face's (u, v) rectangle is cut into SPLIT x SPLIT cells for :func:`face_cells`
SPLIT = 4


def face_cells(part, split: int = SPLIT):
    """The faces of ``part`` and OCCT's bounding boxes ``(F, split², 2, 3)`` of the cells
    of each face's (u, v) rectangle: the box ``BRepBndLib`` gives a face is
    ``BndLib_AddSurface`` over that whole rectangle (a plane's from its edges), so the cells,
    grown by the largest tolerance of the face's edges and vertices, hold the face as surely
    and far more tightly (a cylinder's box holds the whole ring
    around a ribbon passing inside it).  A plane keeps its one box."""
    faces, whole = face_boxes(part)
    cells = np.repeat(whole[:, None], split * split, axis=1)
    for k, face in enumerate(faces):
        face = TopoDS.Face(face)
        surface = BRepAdaptor_Surface(face)
        if surface.GetType() == GeomAbs_Plane:
            continue
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        us, vs = np.linspace(u0, u1, split + 1), np.linspace(v0, v1, split + 1)
        # an edge's curve lies within its tolerance of the surface, a vertex within its own
        tol = max(BRep_Tool.MaxTolerance_s(face, kind) for kind in (TopAbs_FACE, TopAbs_EDGE, TopAbs_VERTEX))
        for i in range(split):
            for j in range(split):
                box = Bnd_Box()
                BndLib_AddSurface.Add_s(surface, us[i], us[i + 1], vs[j], vs[j + 1], tol, box)
                cells[k, i * split + j] = np.reshape(box_limits(box), (2, 3))
    return faces, cells
