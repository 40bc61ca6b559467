"""The p-curves of a face's edges (``BRepAdaptor_Curve2d``) as plain data, for vectorized
evaluation on the NumPy side, and their images beside the edges' 3-D curves.

:func:`face_pcurves` reads every edge of a face once: its parameter range, its sign in
the face (``-1`` for a reversed edge), the breaks of its ``GeomAbs_CN`` intervals and
the 2-D curve itself -- a line (origin, direction), a circle (centre, axes, radius), a
B-spline (poles, weights, flat knots, degree) or any other type, which
:func:`adaptor_d1` samples point by point through the record's OCCT ``adaptor``.  Lines, circles and B-splines are then
evaluated for all Gauss nodes at once (:mod:`surfmod.mass.boundary`), instead of one
``Geom2dAdaptor.D1`` call per node; :func:`faces_pcurves` reads the B-spline p-curves
of many faces through one binary table.
"""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
from OCP.BRepGProp import BRepGProp
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.GeomAbs import GeomAbs_BSplineCurve, GeomAbs_Circle, GeomAbs_CN, GeomAbs_Line
from OCP.TopAbs import TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopoDS import TopoDS, TopoDS_Iterator
from OCP.gp import gp_Pnt2d, gp_Vec2d

from ..eval.basis import knots_inside
from .geom import bspline_curves, read_bspline_curve
from .arrays import pnt, xyz, xyz_many
from .guard import kernel
from .bindings import TColStd_Array1OfReal, TopTools_IndexedMapOfShape
from .topo import geometric_edges, pcurve_points


def _xy(p) -> np.ndarray:
    return np.array(p.Coord())


def _bspline_data(pc):
    """Poles ``(n, 2)``, weights, flat knots and degree of a B-spline p-curve; None for a periodic curve whose edge range leaves its
    first period (its unwrapped form would continue the end span there instead)."""
    b = pc.BSpline()
    if b.IsPeriodic():
        b = b.Copy()  # OCP returns the derived type
        b.SetNotPeriodic()
        if pc.FirstParameter() < b.FirstParameter() or pc.LastParameter() > b.LastParameter():
            return None
    data = read_bspline_curve(b)
    data["points"] = data["points"][:, :2]  # (u, v), as the non-periodic ones
    return data


def face_pcurves(face) -> list[dict]:
    """Per edge of ``face`` (outer wire and holes, as ``TopExp_Explorer`` visits them):
    ``{"kind", "wire", "range", "sign", "breaks", ...}`` (``wire``: index of the edge's
    wire; a B-spline not periodic gets its ``breaks`` from its knots in
    :func:`surfmod.mass.boundary.taylor_pieces`) where ``kind`` is ``"line"`` (``origin``,
    ``direction``: ``P(t) = origin + t direction``), ``"circle"`` (``centre``, ``x``, ``y``,
    ``radius``: ``P(t) = centre + radius (cos t x + sin t y)``), ``"bspline"`` (``points``
    ``(n, 2)``, ``weights``, ``knots``, ``degree``) or ``"other"``; every record carries its ``adaptor``
    (see :func:`adaptor_d1`), the reference the data-based evaluation is tested against.

    >>> import build123d as bd
    >>> pcs = face_pcurves(bd.Face(bd.Wire.make_circle(1.0)).wrapped)
    >>> [(p["kind"], p["sign"]) for p in pcs]
    [('circle', 1.0)]
    """
    return faces_pcurves([face])[0]


def faces_pcurves(faces: list) -> list[list[dict]]:
    """:func:`face_pcurves` of many faces (a part's), their B-spline p-curves read through
    one binary table for all of them rather than one per face.

    >>> import build123d as bd
    >>> box = bd.Box(1, 2, 3)
    >>> [len(pcs) for pcs in faces_pcurves([f.wrapped for f in box.faces()])]
    [4, 4, 4, 4, 4, 4]
    """
    splines, lines, out = [], [], []
    with kernel("BRepAdaptor_Curve2d (face p-curves)"):
        for face in faces:
            out.append(_face_records(face, splines, lines))
        for (rec, _), data in zip(splines, bspline_curves([b for _, b in splines], 2)):
            rec.update(kind="bspline", points=data["points"], weights=data["weights"], knots=data["knots"],
                       degree=data["degree"])
    if lines:  # every straight p-curve's data in one array (rows are views: no array per line)
        data = np.array([d for _, d in lines])  # (L, 6): origin, direction, range
        for k, (rec, _) in enumerate(lines):
            rec["origin"], rec["direction"], rec["breaks"] = data[k, :2], data[k, 2:4], data[k, 4:]
            rec["line"] = data[k]  # all six: origin, direction, range
    return out


# enum members as ints: comparing pybind11 enums costs several times an int comparison,
# and these run once per edge of a part
_LINE, _CIRCLE, _BSPLINE, _REVERSED = int(GeomAbs_Line), int(GeomAbs_Circle), int(GeomAbs_BSplineCurve), int(TopAbs_REVERSED)


def _face_records(face, splines: list, lines: list) -> list[dict]:
    """The records of :func:`face_pcurves` of one face.  Non-periodic B-spline p-curves
    are appended to ``splines`` as ``(record, curve)``, straight ones to ``lines`` as
    ``(record, (origin, direction, range))``, for the caller to read in bulk."""
    out = []
    to_edge = TopoDS.Edge
    # the face's wires and their edges as TopExp_Explorer visits them (children in order,
    # orientations composed), by TopoDS_Iterator: no explorer stack per wire
    wires = TopoDS_Iterator(face)
    wire_index = -1
    while wires.More():
        wire = wires.Value()
        wires.Next()
        if wire.ShapeType() != TopAbs_WIRE:
            continue
        wire_index += 1
        edges = TopoDS_Iterator(wire)
        while edges.More():
            edge = to_edge(edges.Value())
            edges.Next()
            pc = BRepAdaptor_Curve2d(edge, face)
            f, l = pc.FirstParameter(), pc.LastParameter()
            kind = int(pc.GetType())
            rec = {
                "wire": wire_index,
                "range": (f, l),
                "sign": -1.0 if int(edge.Orientation()) == _REVERSED else 1.0,
                "adaptor": pc,
            }
            if kind == _LINE:  # analytic: one smooth interval, its ends
                lin = pc.Line()
                rec["kind"] = "line"
                lines.append((rec, lin.Location().Coord() + lin.Direction().Coord() + (f, l)))
            elif kind == _CIRCLE:
                c = pc.Circle()
                ax = c.Position()
                rec.update(kind="circle", breaks=np.array([f, l]), centre=_xy(ax.Location()), x=_xy(ax.XDirection()),
                           y=_xy(ax.YDirection()), radius=c.Radius())
            else:
                if kind == _BSPLINE and not (b := pc.BSpline()).IsPeriodic():
                    splines.append((rec, b))  # read by the caller, all in one binary table
                    out.append(rec)  # its breaks from its knots: mass.boundary.taylor_pieces
                    continue
                rec["breaks"] = (_periodic_knot_breaks(b, f, l) if kind == _BSPLINE
                                 else _intervals(pc, pc.NbIntervals(GeomAbs_CN)))
                if kind == _BSPLINE and (data := _bspline_data(pc)) is not None:
                    rec.update(kind="bspline", **data)
                else:
                    rec.update(kind="other")
            out.append(rec)
    return out


def _intervals(pc, n: int) -> np.ndarray:
    """The ``n + 1`` bounds of the ``GeomAbs_CN`` intervals of a p-curve adaptor."""
    arr = TColStd_Array1OfReal(1, n + 1)
    pc.Intervals(arr, GeomAbs_CN)
    return np.array([arr.Value(i) for i in range(1, n + 2)])


def _periodic_knot_breaks(b, f: float, l: float) -> np.ndarray:
    """The breaks of a periodic B-spline p-curve ``b`` over ``[f, l]``: its knots, repeated
    every period, strictly inside, between the ends (see
    :func:`surfmod.mass.breaks.spline_breaks` for why not OCCT's intervals)."""
    knots = [b.Knot(i) for i in range(1, b.NbKnots() + 1)]
    return np.concatenate([[f], knots_inside(knots, f, l, b.LastParameter() - b.FirstParameter()), [l]])


def adaptor_d1(adaptor, t: np.ndarray) -> np.ndarray:
    """``(N, 4)``: ``u, v, du/dt, dv/dt`` of a 2-D curve adaptor at parameters ``t`` (one
    OCCT call per parameter: only for p-curve types :func:`face_pcurves` cannot hand over
    as data).

    >>> import build123d as bd
    >>> from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    >>> face = bd.Face(bd.Wire.make_circle(1.0)).wrapped
    >>> edge = bd.Face(face).edges()[0].wrapped
    >>> adaptor_d1(BRepAdaptor_Curve2d(edge, face), np.array([0.0])).round(12).tolist() == [[1, 0, 0, 1]]
    True
    """
    p, d = gp_Pnt2d(), gp_Vec2d()
    out = np.empty((len(t), 4))
    with kernel("Geom2dAdaptor D1 (p-curve)"):
        for i, ti in enumerate(t):
            adaptor.D1(float(ti), p, d)
            out[i] = (p.X(), p.Y(), d.X(), d.Y())
    return out


def _length(edge) -> float:
    props = GProp_GProps()
    BRepGProp.LinearProperties_s(edge, props)
    return props.Mass()


def edge_images(shape, samples: int) -> list[dict]:
    """Per geometric, non-degenerate edge of ``shape`` with a 3-D curve: ``{"edge"`` (index in
    ``TopExp``'s edge map, from 0), ``"tolerance"``, ``"length"``, ``"curve"`` (the located
    3-D curve and its range, for :func:`distances_to_curve`), ``"faces"`` (indices in the face
    map, from 0; a seam's face once), ``"images"`` (per face the ``(samples, 3)`` image of the
    p-curve at equally spaced parameters) and ``"along"`` (the 3-D curve at those
    parameters)``}``."""
    out = []
    with kernel("edge images (BRepAdaptor_Curve2d)"):
        fmap = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(shape, TopAbs_FACE, fmap)
        for edge_index, edge, edge_faces in geometric_edges(shape):
            range_ = BRepAdaptor_Curve(edge)
            first, last = range_.FirstParameter(), range_.LastParameter()
            curve = BRep_Tool.Curve_s(edge, first, last)  # a located copy of the 3-D curve
            if curve is None:
                continue
            faces, images, along = [], [], []
            for face in edge_faces:
                index = -1 if face.IsNull() else fmap.FindIndex(face) - 1
                if index < 0 or index in faces:  # no face, or a seam edge: the same face twice
                    continue
                faces.append(index)
                t, pts = pcurve_points(edge, face, samples)
                images.append(pts)
                along.append(xyz_many((curve.Value(x) for x in t.tolist()), len(t)))
            out.append({"edge": edge_index, "tolerance": float(BRep_Tool.Tolerance_s(edge)), "length": _length(edge),
                        "curve": (curve, first, last), "faces": faces, "images": images, "along": along})
    return out


def distances_to_curve(curve, points: np.ndarray) -> np.ndarray:
    """Distance of each point to a bounded 3-D curve ``(curve, first, last)``
    (``GeomAPI_ProjectPointOnCurve``; with no orthogonal foot, beyond the curve's ends, the
    nearer end's distance)."""
    curve, first, last = curve
    out = np.empty(len(points))
    with kernel("GeomAPI_ProjectPointOnCurve"):
        project = GeomAPI_ProjectPointOnCurve()
        project.Init(curve, first, last)
        ends = xyz(curve.Value(first)), xyz(curve.Value(last))
        for k, p in enumerate(points):
            project.Perform(pnt(p))
            out[k] = project.LowerDistance() if project.NbPoints() > 0 else min(
                np.linalg.norm(p - ends[0]), np.linalg.norm(p - ends[1]))
    return out


def edge_deviation_samples(shape, samples: int) -> list[tuple]:
    """Per geometric edge of ``shape``: ``(points, images, length)``: ``samples`` points of
    its 3-D curve equally spaced in its parameter, the image of its p-curve on each of its
    faces (a seam's face twice) at as many points, as ``BRepCheck`` samples them, and its
    length."""
    out = []
    with kernel("edge deviations"):
        for _, edge, edge_faces in geometric_edges(shape):
            c3 = BRepAdaptor_Curve(edge)
            t = np.linspace(c3.FirstParameter(), c3.LastParameter(), samples)
            p3 = xyz_many((c3.Value(x) for x in t.tolist()), samples)
            out.append((p3, [pcurve_points(edge, face, samples)[1] for face in edge_faces], _length(edge)))
    return out
