"""surfmod objects as build123d shapes, for the viewer build123d users already have.

:func:`to_build123d` turns what surfmod computes into build123d shapes that the OCP CAD
Viewer's ``show()`` draws: surfaces and curves become their exact faces and edges, meshes
and analysis results become triangle faces, tool paths and machining jobs become wires
coloured per operation (rapids apart from cuts), with the part and the stock.  Compound
nodes carry a ``label`` and a ``color`` and hold their parts as ``children``, which the
viewer shows as a tree one can switch on and off.

>>> import surfmod as sm
>>> view = sm.to_build123d(sm.sphere(2.0))
>>> type(view).__name__
'Face'
"""

from __future__ import annotations

import numpy as np

from ..cam.job import Job
from ..cam.roughing import RAPID
from ..cam.toolpath import Toolpath
from ..curve import Curve
from ..errors import SurfmodError
from ..meshing.analyze import Analysis
from ..meshing.polymesh import Mesh
from ..occ.polyshapes import as_shape, dress, group, polyline, triangles
from ..surface import Surface

#: one colour per operation, in order (the viewer's palette is its own)
OPERATION_COLORS = ("royalblue", "darkorange", "forestgreen", "purple", "brown", "teal")
RAPID_COLOR = "red"
PART_COLOR = "lightgray"
#: analysis values fall into this many bands, each one colour from low to high
BAND_COLORS = ("#440154", "#46327e", "#365c8d", "#277f8e", "#1fa187", "#4ac16d", "#a0da39", "#fde725")


def _runs(points: np.ndarray, cutting: np.ndarray):
    """Maximal runs of consecutive moves that all cut (or all are rapid): each run's
    points include the location it starts from, so the wires join up."""
    moving = cutting[1:]
    if not len(moving):
        return
    edges = np.flatnonzero(np.diff(moving.astype(np.int8))) + 1
    for lo, hi in zip(np.r_[0, edges], np.r_[edges, len(moving)]):
        yield bool(moving[lo]), points[lo:hi + 1]


def _moves(points, kinds, color, label):
    """One node per operation: its cutting moves and its rapids, each a compound of wires."""
    cuts, rapids = [], []
    for cutting, run in _runs(np.asarray(points, float), np.asarray(kinds) != RAPID):
        wire = polyline(run)
        if wire is not None:
            (cuts if cutting else rapids).append(wire)
    children = []
    if cuts:
        children.append(group(cuts, color=color, label=f"{label} cuts"))
    if rapids:
        children.append(group(rapids, color=RAPID_COLOR, label=f"{label} rapids"))
    return group(children, color=color, label=label)


def _stock(stock) -> object:
    lo, hi = np.asarray(stock, float)
    corners = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
    ring = [0, 1, 3, 2, 0]
    edges = [polyline(corners[ring], label="bottom"), polyline(corners[np.add(ring, 4)], label="top")]
    edges += [polyline(corners[[i, i + 4]], label="side") for i in range(4)]
    return group(edges, color="gray", label="stock")


def _job(job: Job):
    ops = [_moves(op.motion.points, op.motion.kind, OPERATION_COLORS[i % len(OPERATION_COLORS)],
                  f"{i + 1} {op.name} T{op.tool.number}")
           for i, op in enumerate(job.operations)]
    part = group([as_shape(job.part)], color=PART_COLOR, label="part")
    return group([part, _stock(job.stock), *ops], label="job")


def _analysis(result: Analysis):
    values = result.values
    finite = values[np.isfinite(values)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    bands = [[] for _ in BAND_COLORS]
    for k, patch in enumerate(result.patches):
        tri_values = patch.values[patch.triangles].mean(axis=1)
        scaled = (tri_values - lo) / (hi - lo) if hi > lo else np.zeros(len(tri_values))
        index = np.clip((np.nan_to_num(scaled) * len(BAND_COLORS)).astype(int), 0, len(BAND_COLORS) - 1)
        for b in np.unique(index):
            bands[b].append(triangles(patch.points, patch.triangles[index == b], label=f"patch {k}"))
    nodes = [group(parts, color=color, label=f"{result.kind} band {b + 1} of {len(BAND_COLORS)}")
             for b, (parts, color) in enumerate(zip(bands, BAND_COLORS)) if parts]
    return group(nodes, label=f"analysis {result.kind} ({lo:.4g} .. {hi:.4g})")


def to_build123d(obj, *, color=None, label: str | None = None):
    """``obj`` as build123d shapes that ``ocp_vscode.show()`` (or any build123d tool) takes.

    Parameters
    ----------
    obj
        A surfmod surface or curve (its exact ``face()`` / ``edge()``), a :class:`~surfmod.Mesh`
        (triangle faces), an analysis result of :func:`~surfmod.analyze` (its triangles in
        eight colour bands from the lowest value to the highest), a
        :class:`~surfmod.cam.toolpath.Toolpath`, a machining :class:`~surfmod.cam.job.Job`
        (the part, the stock's edges, and per operation its cuts and its rapids), a build123d
        shape (returned as it is), or a list or tuple of these (one compound of them).
    color
        A build123d ``Color`` argument (a name such as ``"orange"`` or an RGB(A) tuple) for
        the top node; the nodes inside keep their own colours.
    label
        The top node's label (default: what the object is).

    Returns
    -------
    build123d.Shape
        A ``Face``, ``Edge``, ``Wire`` or ``Compound`` (with ``children`` for jobs, tool
        paths, meshes and analyses).

    Raises
    ------
    SurfmodError
        For an object surfmod cannot show (naming its type), or a mesh above
        :data:`surfmod.occ.polyshapes.MAX_TRIANGLES` faces.
    """
    if hasattr(obj, "wrapped") and not isinstance(obj, (Surface, Curve)):
        return obj
    if isinstance(obj, (list, tuple)):
        out = group([to_build123d(o) for o in obj], label=label or "objects")
    elif isinstance(obj, Surface):
        out = obj.face()
    elif isinstance(obj, Curve):
        out = obj.edge()
    elif isinstance(obj, Mesh):
        out = triangles(obj.vertices, obj.faces, color=PART_COLOR, label="mesh")
    elif isinstance(obj, Analysis):
        out = _analysis(obj)
    elif isinstance(obj, Toolpath):
        # a finishing path is one continuous feed move, links and staircases included
        out = _moves(obj.points, np.ones(len(obj.points), np.int8), OPERATION_COLORS[0], f"toolpath {obj.tool}")
    elif isinstance(obj, Job):
        out = _job(obj)
    else:
        raise SurfmodError(f"obj: cannot show a {type(obj).__name__} (expected surfmod surfaces, curves, meshes, "
                           "analyses, tool paths, jobs or build123d shapes)")
    return dress(out, color, label)
