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
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon,
                                BRepBuilderAPI_MakeVertex)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
from OCP.Extrema import Extrema_ExtFlag_MIN
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

from surfmod.occ.bindings import box_limits


def material(shape):
    """The faces of ``shape`` as one compound: free edges and vertices of a STEP file
    (construction wires) are not material a tool can cut."""
    from OCP.BRep import BRep_Builder
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Compound

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
    ``radius`` minus it.  Each ribbon is measured against the faces whose bounding boxes
    come within ``radius`` of its own: a face farther away cuts nothing, and the distance
    to the others is the distance to the whole part wherever it is below ``radius``."""
    faces, boxes = face_boxes(getattr(part, "wrapped", part))
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


def flat_cuts(part, points: np.ndarray, radius: float, depth: float, top: float) -> list[int]:
    """Indices of moves where the flat end, shrunk by ``depth``, meets the part.  Each
    cylinder is measured against the faces whose bounding boxes meet its own (the same
    distance as against the whole part, found faster)."""
    faces, boxes = face_boxes(getattr(part, "wrapped", part))
    rho = radius - depth
    bad = []
    for i in range(len(points) - 1):
        a, b = points[i], points[i + 1]
        n = int(max(np.ceil(np.linalg.norm(b[:2] - a[:2]) / (radius / 20)),
                    np.ceil(abs(b[2] - a[2]) / (depth / 4)) if np.linalg.norm(b[:2] - a[:2]) > 0 else 0, 1))
        lo = np.r_[np.minimum(a, b)[:2] - rho, min(a[2], b[2]) + depth]
        hi = np.r_[np.maximum(a, b)[:2] + rho, top]
        near = _near(boxes, lo, hi)
        if not len(near):
            continue
        target = compound(faces[k] for k in near)
        for t in np.linspace(0.0, 1.0, n + 1):
            p = a + t * (b - a)
            axis = gp_Ax2(gp_Pnt(float(p[0]), float(p[1]), float(p[2] + depth)), gp_Dir(0, 0, 1))
            cutter = BRepPrimAPI_MakeCylinder(axis, rho, top - p[2] - depth).Shape()
            # a vertex CLEAR below the bottom's centre: OCCT then skips every pair of
            # sub-shapes whose boxes stand farther apart than that (a third less work on
            # occt_screw), and a distance of 1e-9 or less is found as before
            mark = BRepBuilderAPI_MakeVertex(gp_Pnt(float(p[0]), float(p[1]), float(p[2] + depth - CLEAR))).Vertex()
            dist = BRepExtrema_DistShapeShape(cutter, compound([target, mark]), Extrema_ExtFlag_MIN)
            assert dist.IsDone()
            if dist.Value() <= 1e-9:
                bad.append(i)
                break
    return bad


#: how far below a flat end's placement :func:`flat_cuts` puts its vertex (above the 1e-9
#: that counts as meeting the part)
CLEAR = 1e-6


def _near_strips(boxes: np.ndarray, centre: np.ndarray, top: float, radius: float) -> np.ndarray:
    """Indices of the faces whose boxes ``(F, 2, 3)`` come nearer than ``radius`` to the
    ribbon over the polyline ``centre`` up to ``top``: the ribbon lies in the union of the
    boxes of its strips (a segment and the wall above it), and a face's box is no nearer
    to it than the least Euclidean distance between the face's box and a strip's box
    (on Ventilator 10 % fewer faces than the piece's box grown by ``radius``)."""
    lo = np.minimum(centre[:-1], centre[1:])
    hi = np.maximum(centre[:-1], centre[1:])
    hi[:, 2] = np.maximum(hi[:, 2], top)
    gap = np.maximum(0.0, np.maximum(lo[None] - boxes[:, None, 1], boxes[:, None, 0] - hi[None]))
    return np.flatnonzero(np.sqrt((gap * gap).sum(-1)).min(1) < radius)


def _near(boxes: np.ndarray, lo, hi) -> np.ndarray:
    """Indices of the faces whose boxes ``(F, 2, 3)`` meet the box ``lo``-``hi``."""
    return np.flatnonzero(np.all((boxes[:, 0] <= hi) & (boxes[:, 1] >= lo), axis=1))


def compound(shapes):
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for s in shapes:
        builder.Add(compound, s)
    return compound


def face_boxes(part):
    """The faces of ``part`` and their OCCT bounding boxes ``(F, 2, 3)``."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

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

