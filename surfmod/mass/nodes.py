"""Stage four of the mass pipeline (:mod:`surfmod.mass`): faces prepared for quadrature
(:class:`MassFace`) and their nodes and weights (:func:`face_nodes`, :func:`faces_nodes`,
:func:`plane_nodes`): tensor Gauss–Legendre on a face bounded by its parameter rectangle,
Green's theorem on a trimmed one, with the fewest nodes that keep round-off.
See :doc:`/guide/uses` (section "How a face is integrated").
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..construct.curves import Line
from ..construct.elementary import (ConicalSurface, CylindricalSurface, ElementarySurface, PlaneSurface, SphericalSurface,
                                    ToroidalSurface)
from ..construct.extrusion import TabulatedCylinder
from ..construct.revolution import RevolutionSurface
from ..nets.bspline import BSplineCurve, BSplineSurface
from .breaks import ANGULAR_PIECE, direction_breaks, interval_breaks, is_face, knot_breaks, patch_breaks
from .boundary import PIECES, PcurveTable, boundaries, pcurve_crossings, pcurve_d1, piece_spans, taylor_pieces  # noqa: F401 (re-exported)
from .rules import (GridJob, exact_order, gauss, green_layout, grids_nodes, inner_nodes,  # noqa: F401
                        interpolation_points)

#: relative tolerance (to the box size) for "this p-curve lies on the face box's border"
RECTANGLE_RTOL = 1e-7

#: p-curves that meet within this (relative to the face box) at every vertex close the boundary
CLOSURE_RTOL = 1e-10

#: a Green grid serves boundary nodes up to this fraction of its outer span beyond it
GRID_REACH = 1e-3
#: the grid's own work (Lagrange and antiderivative weights, per-cell sums), in evaluated
#: nodes: below this saving node-by-node Gauss is faster
GRID_OVERHEAD = 1500

def _curve_degree(curve):
    if isinstance(curve, Line):
        return 1
    if isinstance(curve, BSplineCurve) and curve.weights is None:
        return int(curve.degree)
    return None


# the degrees of the elementary surfaces by exact type: most faces of real parts, where
# the isinstance chain of direction_degree (abstract base classes) costs more than the rest
_ELEMENTARY_DEGREES = {PlaneSurface: (1, 1), CylindricalSurface: (None, 1), ConicalSurface: (None, 1),
                       SphericalSurface: (None, None), ToroidalSurface: (None, None)}


def _degrees(surface) -> tuple:
    """``(direction_degree(surface, 0), direction_degree(surface, 1))``."""
    known = _ELEMENTARY_DEGREES.get(type(surface))
    return known if known is not None else (direction_degree(surface, 0), direction_degree(surface, 1))


def direction_degree(surface, direction: int):
    """Polynomial degree of ``surface`` along ``direction`` (0: u, 1: v), or None where
    it is not a polynomial (angles, rational splines, offsets).

    >>> import surfmod as sm
    >>> c = sm.from_face(__import__("build123d").Cylinder(1, 2).faces()[0]).surface
    >>> direction_degree(c, 0), direction_degree(c, 1)
    (None, 1)
    """
    if isinstance(surface, PlaneSurface):
        return 1
    if isinstance(surface, (CylindricalSurface, ConicalSurface)):
        return 1 if direction == 1 else None
    if isinstance(surface, BSplineSurface):  # Bézier surfaces included
        return int(surface.degree[direction]) if surface.weights is None else None
    if isinstance(surface, TabulatedCylinder):
        return 1 if direction == 1 else _curve_degree(surface.curve)
    if isinstance(surface, RevolutionSurface):
        return _curve_degree(surface.profile) if direction == 1 else None
    return None


def evaluators(obj):
    """``(evaluate, grid_evaluate)``: the partials of a face read back with
    :func:`surfmod.from_face` (or of a surfmod surface) at points ``(u, v)`` and on a
    tensor grid ``us × vs`` (``(nu, nv, K, K, 3)``), as its ``_derivatives`` and
    ``_grid_derivatives`` give them (``grid_evaluate`` None: evaluate point by point).  On
    planes, cylinders, cones, spheres and tori the trigonometry of a grid runs on its
    lines, and the frame is applied to the partials in the frame's axes (their
    ``_coefficients``) by one matrix product, where the surfaces' own evaluators broadcast
    every point against each axis (three passes with an innermost dimension of 3, most of
    the evaluation's time).

    >>> import surfmod as sm, build123d as bd
    >>> face = sm.from_face(bd.Torus(5, 1).faces()[0])
    >>> evaluate, grid = evaluators(face)
    >>> u, v = np.array([0.3, 1.2]), np.array([2.0, 5.5])
    >>> bool(np.allclose(evaluate(u, v, 1), face._derivatives(u, v, 1), rtol=0, atol=1e-14))
    True
    >>> grid(u, v, 1).shape
    (2, 2, 2, 2, 3)
    """
    face = is_face(obj)
    surf = obj.surface if face else obj
    if type(surf) not in _ELEMENTARY_DEGREES and not isinstance(surf, ElementarySurface):
        # splines, sweeps, offsets: point by point (their tensor evaluators pay off only
        # on grids much larger than a face's quadrature nodes)
        return obj._derivatives, None
    axes, origin = np.array([surf.x_dir, surf.y_dir, surf.z_dir]), surf.origin
    wrap = obj._wrap if face else (lambda t, direction: t)  # a face evaluates where it lives (periodic wrap)

    def combine(fx, fy, fz):
        f = np.stack([fx, fy, fz], axis=-1)
        out = (f.reshape(-1, 3) @ axes).reshape(f.shape)
        out[..., 0, 0, :] += origin
        return out

    def evaluate(u, v, order):
        return combine(*surf._coefficients(wrap(u, 0), wrap(v, 1), order))

    def grid_evaluate(us, vs, order):
        return combine(*surf._coefficients(wrap(us, 0)[:, None], wrap(vs, 1)[None, :], order))

    return evaluate, grid_evaluate


# -- faces -----------------------------------------------------------------------------------
@dataclass
class MassFace:
    """One face prepared for quadrature: evaluator, box, break points, sign, p-curves and
    per direction the polynomial degree (or None)."""

    evaluate: object
    bounds: tuple
    breaks: tuple
    sign: float
    degrees: tuple
    pcurves: list | None  # None: the face is its whole parameter rectangle
    plane: bool = False
    frame: tuple | None = None  # planes: origin, x, y (S = O + u X + v Y)
    table: PcurveTable | None = None  # the p-curves as arrays (built once per face)
    # per direction: its breaks are only the eighth turns of an analytic angle (no knot)
    angular: tuple = (False, False)
    # Gauss nodes on the p-curves per order, when computed for many faces at once
    boundary: dict = field(default_factory=dict)
    # the same partials as ``evaluate`` on a tensor grid ``us × vs`` (``(nu, nv, 2, 2, 3)``)
    grid_evaluate: object = None
    # ``(table, first row)``: the face's p-curves are rows of a part's shared PcurveTable
    rows: tuple | None = None

    @property
    def natural(self) -> bool:
        return self.pcurves is None


def _border_tolerance(bounds: np.ndarray) -> np.ndarray:
    """``(R, 4)``: how far from each border line of the boxes ``bounds`` (``(R, 4)``) a point still lies on it."""
    u0, u1, v0, v1 = bounds.T
    tol = np.stack([RECTANGLE_RTOL * np.maximum(1.0, u1 - u0), RECTANGLE_RTOL * np.maximum(1.0, v1 - v0)], axis=1)
    return tol[:, [0, 0, 1, 1]]


def _lines_on_box_border(lines: list, bounds: np.ndarray) -> np.ndarray:
    """:func:`_records_on_box_border` of straight p-curves only (``bounds`` ``(R, 4)``, per
    record): both ends of each on one border line, a few array operations for all of them
    without a :class:`PcurveTable`."""
    bounds = np.asarray(bounds, dtype=float)
    tol = _border_tolerance(bounds)
    data = np.array([rec["line"] if "line" in rec else np.concatenate([rec["origin"], rec["direction"], rec["range"]])
                     for rec in lines])  # (origin, direction, range) rows, as faces_pcurves reads them
    o, d, r = data[:, :2], data[:, 2:4], data[:, 4:]
    first = np.abs((o + r[:, :1] * d)[:, [0, 0, 1, 1]] - bounds) <= tol
    last = np.abs((o + r[:, 1:] * d)[:, [0, 0, 1, 1]] - bounds) <= tol
    return np.any(first & last, axis=1)


def _records_on_box_border(table: PcurveTable, bounds: np.ndarray) -> np.ndarray:
    """Per record of ``table``: whether it runs along the border of its face box
    (``bounds`` ``(R, 4)``, per record): a straight p-curve iff both of its ends lie on
    one border line, others at seven samples each (all p-curves in one evaluation)."""
    bounds = np.asarray(bounds, dtype=float)
    tol = _border_tolerance(bounds)
    straight = table.kind == 0
    samples = np.array([0.0, 0.137, 0.291, 0.5, 0.643, 0.871, 1.0])  # ends first, then inside
    ranges = np.array([rec["range"] for rec in table.records])
    f, l = ranges[:, :1], ranges[:, 1:]
    t = f + (l - f) * samples  # (R, 7); lines use the first two columns (their ends)
    t[straight, 1] = l[straight, 0]
    q = table.d1(np.repeat(np.arange(len(ranges)), len(samples)), t.ravel())[:, :2].reshape(len(ranges), len(samples), 2)
    on = np.abs(q[:, :, [0, 0, 1, 1]] - bounds[:, None, :]) <= tol[:, None, :]  # (R, 7, 4)
    lines_ok = np.any(on[:, 0] & on[:, 1], axis=1)
    curves_ok = np.all(np.any(on, axis=2), axis=1)
    return np.where(straight, lines_ok, curves_ok)


def _linspace(lo: float, hi: float, num: int) -> np.ndarray:
    """``np.linspace(lo, hi, num)`` for floats, the same values (``arange · step + lo``, the
    last point ``hi``) without its general argument handling, which costs more than the
    few points a face's angular breaks are.

    >>> bool(np.array_equal(_linspace(0.3, 2.9, 7), np.linspace(0.3, 2.9, 7)))
    True
    """
    out = np.arange(num) * ((hi - lo) / (num - 1)) + lo
    out[-1] = hi
    return out


def _mass_breaks(face, lo: float, hi: float, direction: int) -> np.ndarray:
    """:func:`surfmod.mass.breaks.patch_breaks` (angular directions without its general
    merging: equal pieces of at most an eighth turn, the same points) and whether the
    direction is an analytic angle (its breaks are no knots)."""
    b = direction_breaks(face, direction)
    if b is None and hi - lo > 1e-9:  # one polynomial piece (planes, axes of cylinders)
        return np.array([lo, hi]), False
    if isinstance(b, str) and hi - lo > 1e-9:
        return _linspace(lo, hi, max(int(np.ceil((hi - lo) / ANGULAR_PIECE - 1e-9)), 1) + 1), True
    return patch_breaks(face, lo, hi, direction, face.periods[direction]), isinstance(b, str)


def mass_faces(read: list, pcurves: list) -> list:
    """:func:`mass_face` of every face of a part (``pcurves`` per face, their B-splines'
    Taylor pieces built); the rectangle test of all faces with curved p-curves runs in
    one evaluation of one :class:`PcurveTable` (:func:`_records_on_box_border`).

    >>> import surfmod as sm, build123d as bd
    >>> from surfmod.occ.pcurves import faces_pcurves
    >>> read = [sm.from_face(f) for f in bd.Cylinder(1, 2).faces()]
    >>> pcs = faces_pcurves([f.face_shape for f in read])
    >>> taylor_pieces([r for p in pcs for r in p])
    >>> [m.natural for m in mass_faces(read, pcs)]
    [True, False, False]
    """
    one_wire = [i for i, pcs in enumerate(pcurves) if pcs and all(rec["wire"] == 0 for rec in pcs)]
    straight = [i for i in one_wire if all(rec["kind"] == "line" for rec in pcurves[i])]
    curved = sorted(set(one_wire) - set(straight))
    natural = {i: False for i in range(len(read))}
    shared = {}
    for test, check in ((straight, _lines_on_box_border), (curved, _records_on_box_border)):
        if test:
            records = [rec for i in test for rec in pcurves[i]]
            counts = [len(pcurves[i]) for i in test]
            bounds = np.repeat(np.array([[b for r in read[i].domain for b in r] for i in test]), counts, axis=0)
            if check is _lines_on_box_border:
                ok = check(records, bounds)
            else:  # the table serves the boundary pass of these faces too (prepare_boundaries)
                table = PcurveTable(records)
                ok = check(table, bounds)
                shared = {i: (table, first) for i, first in zip(test, np.cumsum([0] + counts[:-1]).tolist())}
            natural.update(zip(test, np.logical_and.reduceat(ok, np.cumsum([0] + counts[:-1])).tolist()))
    out = [mass_face(f, pcs, natural[i]) for i, (f, pcs) in enumerate(zip(read, pcurves))]
    for i, rows in shared.items():
        out[i].rows = rows
    return out


def mass_face(face, pcurves: list | None = None, natural: bool | None = None) -> MassFace:
    """A :class:`MassFace` for a face read back with :func:`surfmod.from_face` (``pcurves``:
    its :func:`~surfmod.occ.pcurves.face_pcurves`, when already read).

    >>> import surfmod as sm, build123d as bd
    >>> m = mass_face(sm.from_face(bd.Box(1, 1, 1).faces()[0]))
    >>> m.natural, m.degrees, m.plane
    (True, (1, 1), True)

    ``natural``: whether the face is its whole parameter rectangle, when the caller has
    tested it already.
    """
    from ..occ.pcurves import face_pcurves

    u0, u1, v0, v1 = bounds = tuple(b for r in face.domain for b in r)
    surf = face.surface
    plane = isinstance(surf, PlaneSurface)
    angular = (False, False)
    if plane:  # one polynomial piece each way
        breaks = (np.array([u0, u1]), np.array([v0, v1]))
    else:
        (bu, au), (bv, av) = _mass_breaks(face, u0, u1, 0), _mass_breaks(face, v0, v1, 1)
        breaks, angular = (bu, bv), (au, av)
    if pcurves is None:
        pcurves = face_pcurves(face.face_shape)
        taylor_pieces(pcurves)
    table = None
    if natural is not None:  # tested by the caller (mass_faces)
        pass
    elif not pcurves or any(rec["wire"] != 0 for rec in pcurves):
        natural = False
    elif all(rec["kind"] == "line" for rec in pcurves):  # most natural faces: no table needed
        natural = bool(np.all(_lines_on_box_border(pcurves, np.tile(bounds, (len(pcurves), 1)))))
    else:
        table = PcurveTable(pcurves)
        natural = bool(np.all(_records_on_box_border(table, np.tile(bounds, (len(pcurves), 1)))))
    evaluate, grid_evaluate = evaluators(face)
    return MassFace(evaluate, bounds, breaks, -1.0 if face.reversed else 1.0,
                    _degrees(surf), None if natural else pcurves,
                    plane, (surf.origin, surf.x_dir, surf.y_dir) if plane else None, None if natural else table,
                    angular, grid_evaluate=grid_evaluate)


def surface_mass_face(surf) -> MassFace:
    """A :class:`MassFace` for a closed surfmod surface over its whole domain."""
    breaks = []
    for direction, (lo, hi) in enumerate(surf.domain):
        b = direction_breaks(surf, direction)
        # analytic directions without knots: eight pieces keep Gauss converged
        breaks.append(interval_breaks(lo, hi, None, (hi - lo) / 8) if isinstance(b, str) or b is None
                      else knot_breaks(surf, lo, hi, b, direction))
    (u0, u1), (v0, v1) = surf.domain
    evaluate, grid_evaluate = evaluators(surf)
    return MassFace(evaluate, (u0, u1, v0, v1), tuple(breaks), 1.0,
                    _degrees(surf), None, isinstance(surf, PlaneSurface),
                    grid_evaluate=grid_evaluate)


def _direction_order(mf: MassFace, direction: int, order: int) -> tuple[int, bool]:
    p = mf.degrees[direction]
    if p is not None and exact_order(p) <= order:
        return exact_order(p), True
    return order, False


def face_nodes(mf: MassFace, order: int):
    """``(ders (N, 2, 2, 3), weights (N,), exact)``: partials (``Su`` signed by the face's
    orientation, so ``Su × Sv`` is the outward ``n dA``) and weights for the face's
    integrals; ``exact`` says no piece depended on ``order`` (every rule was exact by
    degree), so a lower ``order`` gives the same result."""
    if not mf.natural:  # Green's theorem (see the module notes)
        return faces_nodes([mf], order)[0]
    mu, eu = _direction_order(mf, 0, order)
    mv, ev = _direction_order(mf, 1, order)
    un, uw = piece_spans(mf.breaks[0], mu)
    vn, vw = piece_spans(mf.breaks[1], mv)
    if mf.grid_evaluate is not None:  # u-major, as the repeat/tile below
        ders = mf.grid_evaluate(un, vn, 1).reshape(-1, 2, 2, 3)
    else:
        ders = mf.evaluate(np.repeat(un, vn.size), np.tile(vn, un.size), 1)
    return _signed(mf, ders), np.outer(uw, vw).ravel(), eu and ev


def _signed(mf: MassFace, ders: np.ndarray) -> np.ndarray:
    """``ders`` with ``Su`` negated on a reversed face (``Su × Sv`` the outward ``n dA``)."""
    if mf.sign < 0:
        ders = ders.copy()
        ders[:, 1, 0] *= -1.0
    return ders


def plane_nodes(faces: list) -> tuple[np.ndarray, np.ndarray]:
    """:func:`face_nodes` of many whole-rectangle planar faces at once (``S = O + u X +
    v Y``: 3 × 3 Gauss nodes per face, exact), without a Python call per face.

    >>> import surfmod as sm, build123d as bd
    >>> mfs = [mass_face(sm.from_face(f)) for f in bd.Box(1, 2, 3).faces()]
    >>> d, w = plane_nodes(mfs)
    >>> d.shape, round(float(w.sum()), 12)
    ((54, 2, 2, 3), 22.0)
    """
    x, w = gauss(3)
    b = np.array([mf.bounds for mf in faces])  # (F, 4)
    o, ex, ey = (np.array([mf.frame[i] for mf in faces]) for i in range(3))
    sign = np.array([mf.sign for mf in faces])
    hu, hv = (b[:, 1] - b[:, 0]) / 2, (b[:, 3] - b[:, 2]) / 2
    u = ((b[:, 0] + b[:, 1]) / 2)[:, None] + hu[:, None] * x  # (F, 3)
    v = ((b[:, 2] + b[:, 3]) / 2)[:, None] + hv[:, None] * x
    uu, vv = np.repeat(u, 3, axis=1), np.tile(v, (1, 3))  # (F, 9), u-major as face_nodes
    ders = np.zeros((len(faces), 9, 2, 2, 3))
    ders[:, :, 0, 0] = o[:, None] + uu[..., None] * ex[:, None] + vv[..., None] * ey[:, None]
    ders[:, :, 1, 0] = (sign[:, None] * ex)[:, None]
    ders[:, :, 0, 1] = ey[:, None]
    weights = (hu * hv)[:, None] * np.outer(w, w).ravel()
    return ders.reshape(-1, 2, 2, 3), weights.ravel()


def _largest_gap(mf: MassFace) -> float:
    """Largest distance, relative to the face box, from the end of an edge's p-curve to
    the nearest start of one (in the edges' directions in the face): 0 for a boundary
    whose p-curves join up."""
    u0, u1, v0, v1 = mf.bounds
    scale = np.array([max(u1 - u0, 1e-300), max(v1 - v0, 1e-300)])
    if not mf.pcurves:
        return 0.0
    ends = np.array([rec["ends"] if "ends" in rec else pcurve_d1(rec, np.array(rec["range"]))[:, :2]
                     for rec in mf.pcurves]) / scale  # (E, 2 [start, end], 2)
    backwards = np.array([rec["sign"] <= 0 for rec in mf.pcurves])
    ends[backwards] = ends[backwards, ::-1]  # in the edges' directions in the face
    d = np.linalg.norm(ends[:, None, 1] - ends[None, :, 0], axis=-1)
    return float(d.min(axis=1).max())


def _reaches_beyond(mf: MassFace, P: np.ndarray) -> bool:
    """Whether boundary nodes ``P`` lie beyond the ends of the face's breaks in either
    direction by more than ``CLOSURE_RTOL`` of its extent (not the round-off of a seam)."""
    for d in (0, 1):
        lo, hi = mf.breaks[d][0], mf.breaks[d][-1]
        reach = CLOSURE_RTOL * max(hi - lo, 1e-300)
        if np.any(P[:, d] < lo - reach) or np.any(P[:, d] > hi + reach):
            return True
    return False


def is_conic(mf) -> bool:
    """Whether a trimmed planar face is bounded by straight and circular p-curves only
    (holes, slots, rounded pockets): its boundary's Gauss nodes are then laid directly
    (:func:`surfmod.mass.planes._arc_nodes`), without the boundary pass.

    >>> import surfmod as sm, build123d as bd
    >>> is_conic(mass_face(sm.from_face(bd.Face(bd.Wire.make_circle(2.0)))))
    True
    """
    return bool(mf.plane and not mf.natural and mf.pcurves
                and all(rec["kind"] in ("line", "circle") for rec in mf.pcurves))


def _boundary_rule(mf: MassFace, order: int) -> tuple:
    """The face's entry for :func:`surfmod.mass.boundary.boundaries`: per p-curve the
    Gauss order and whether it is exact, the break lines and their kind."""
    orders, exacts = [], []
    for rec in mf.pcurves:
        if mf.plane and rec["kind"] == "line":
            # G is a polynomial of degree 4 in (u, v), affine along the line: 3 nodes are exact
            orders.append(3)
            exacts.append(True)
        else:
            orders.append(order)
            exacts.append(False)
    return mf.pcurves, orders, exacts, mf.breaks[0][1:-1], mf.breaks[1][1:-1], mf.angular


def face_boundary(mf: MassFace, order: int):
    """``(P, dP, weights, exact)``: Gauss nodes on a trimmed face's p-curves (computed
    now, or taken from :func:`prepare_boundaries`).

    >>> import surfmod as sm, build123d as bd
    >>> disc = mass_face(sm.from_face(bd.Face(bd.Wire.make_circle(1.0))))
    >>> P, dP, w, exact = face_boundary(disc, 12)
    >>> len(w), exact
    (48, False)
    """
    if order in mf.boundary:
        return mf.boundary.pop(order)  # used once: the estimate pass has its own order
    return boundaries([_boundary_rule(mf, order)], mf.table)[0]


def prepare_boundaries(faces: list, order: int) -> None:
    """The Gauss nodes on the p-curves of every trimmed face of ``faces`` at ``order``, in
    one pass for all of them (:func:`surfmod.mass.boundary.boundaries`), kept for
    :func:`face_nodes` / :func:`surfmod.mass.planes.plane_moments`.

    >>> import surfmod as sm, build123d as bd
    >>> part = bd.Cylinder(1.0, 4.0) - bd.Box(4, 4, 4).rotate(bd.Axis.X, 30).translate((0, 0, 2.5))
    >>> faces = [mass_face(sm.from_face(f)) for f in part.faces()]
    >>> prepare_boundaries(faces, 12)  # the cut side and the slanted ellipse; the bottom disc is closed form
    >>> sorted(len(f.boundary) for f in faces)
    [0, 1, 1, 1]
    """
    # planar faces bounded by lines and circles need none (their nodes are laid directly
    # by surfmod.mass.planes)
    trimmed = [mf for mf in faces if not mf.natural and mf.pcurves and not is_conic(mf)]
    if trimmed:
        table = None
        if all(mf.rows is not None and mf.rows[0] is trimmed[0].rows[0] for mf in trimmed):
            # their p-curves are rows of the table mass_faces built: taken, not rebuilt
            table = trimmed[0].rows[0].subset(np.concatenate(
                [np.arange(mf.rows[1], mf.rows[1] + len(mf.pcurves)) for mf in trimmed]))
        for mf, got in zip(trimmed, boundaries([_boundary_rule(mf, order) for mf in trimmed], table)):
            mf.boundary[order] = got


class _GreenPlan:
    """What :func:`faces_nodes` decides for a trimmed face before its grids are built: the inner
    direction ``k``, the boundary nodes ``P`` with their weights and layout, which of them
    go onto grids (``job``, a :class:`~surfmod.mass.rules.GridJob`, or None) and the
    rest, node by node."""

    __slots__ = ("k", "m_in", "P", "wb", "full", "partial", "rest", "job", "counts", "exact")


def _green_plan(mf: MassFace, order: int, orders, exacts) -> _GreenPlan:
    plan = _GreenPlan()
    P, dP, wt, exact = face_boundary(mf, order)
    # inner direction: the one with fewer inner nodes per boundary node, where the
    # p-curves close up within the face box.  Where they leave a gap (a model whose edges
    # are off its faces), or reach beyond the box (a p-curve a hair outside the surface's
    # knot range, where OCCT's UV bounds stop), the result depends on the direction:
    # the inner integral ends at the box, the outer one follows the p-curve out, and
    # BRepGProp's direction is u from the box's left edge (soarm_Motor1_holder: inner v
    # dropped a sliver below the v range, 5e-4 of a face's area, where BRepGProp keeps it)
    closed = not _reaches_beyond(mf, P) and _largest_gap(mf) <= CLOSURE_RTOL
    cost = [(len(mf.breaks[d]) - 1) * orders[d] for d in (0, 1)]
    k = 1 if closed and cost[1] < cost[0] else 0
    m_in = orders[k]
    # ∫∫ g = ∮ G dv (inner u) = -∮ H du (inner v)
    wb = wt * dP[:, 1] if k == 0 else -wt * dP[:, 0]
    lo = mf.bounds[2 * k]
    if np.sum(wb * (P[:, k] - lo)) < 0:  # boundary traversed clockwise in (u, v): flip
        wb = -wb
    # nodes on p-curves along the inner direction carry no outer differential
    moving = wb != 0.0
    P, wb = P[moving], wb[moving]
    full, partial, q = green_layout(mf, k, P)
    # node by node, or all nodes onto fixed grids per cell: whichever evaluates fewer
    # points.  Grids serve the nodes inside their outer span (p-curves reach a hair
    # beyond the face box, where a short end span must not be extrapolated far)
    obr = mf.breaks[1 - k]
    on_grid = np.abs(2 * P[:, 1 - k] - obr[q] - obr[q + 1]) <= (1 + GRID_REACH) * (obr[q + 1] - obr[q])
    counts = [interpolation_points(mf.degrees[d], order) for d in (k, 1 - k)]
    deepest = np.zeros(len(obr) - 1, int)  # per outer span, the inner spans its nodes reach
    np.maximum.at(deepest, q[on_grid], (full + partial)[on_grid])
    grid = counts[0][0] * counts[1][0] * deepest.sum()
    if grid + GRID_OVERHEAD < m_in * (partial[on_grid].sum() + full[on_grid].sum()):
        Pg = P[on_grid]
        plan.job = GridJob(mf.breaks[k], obr, Pg[:, k], Pg[:, 1 - k], wb[on_grid], full[on_grid], partial[on_grid],
                           q[on_grid])
        plan.counts = (counts[0][0], counts[1][0])
        rest = ~on_grid
        exact = exact and counts[0][1] and counts[1][1] and (exacts[k] or not rest.any())
    else:
        plan.job, plan.counts, rest = None, None, np.ones(len(P), bool)
        exact = exact and exacts[k]
    plan.k, plan.m_in, plan.P, plan.wb, plan.full, plan.partial, plan.rest, plan.exact = (
        k, m_in, P, wb, full, partial, rest, exact)
    return plan


def _green_nodes(mf: MassFace, plan: _GreenPlan, grid):
    """The partials and weights of a planned face: its grid's points (``grid``, from
    :func:`~surfmod.mass.rules.grids_nodes`) first, then the rest node by node."""
    k, rest = plan.k, plan.rest
    parts, weights = [], []
    if grid is not None:  # on the surface's tensor evaluator
        parts.append(grid.derivatives(k, mf.evaluate, mf.grid_evaluate))
        weights.append(grid.weights)
    if rest.any():
        s, other, ws = inner_nodes(mf, k, plan.m_in, plan.P[rest], plan.wb[rest], plan.full[rest], plan.partial[rest])
        parts.append(mf.evaluate(s, other, 1) if k == 0 else mf.evaluate(other, s, 1))
        weights.append(ws)
    if len(parts) == 1:
        return parts[0], weights[0], plan.exact
    return np.concatenate(parts), np.concatenate(weights), plan.exact


#: faces whose grids have at most this many cells (inner × outer spans) share one
#: :func:`~surfmod.mass.rules.grids_nodes` pass, in batches of at most
#: ``GRID_BATCH_CELLS`` padded cells (bounded memory: ``ks kt`` weights per cell)
GRID_BATCH_FACE_CELLS = 64
GRID_BATCH_CELLS = 1024


def faces_nodes(faces: list, order: int) -> list:
    """:func:`face_nodes` of many faces, the same nodes, weights and partials: the Green
    grids of the small trimmed faces (those of a part's many small fillets, tori and cones)
    built in shared passes (:func:`~surfmod.mass.rules.grids_nodes`), where one pass
    per face cost more than its arithmetic.

    >>> import surfmod as sm, build123d as bd
    >>> mfs = [mass_face(sm.from_face(f)) for f in (bd.Cylinder(2, 3) - bd.Box(1, 1, 9).translate((2, 0, 0))).faces()]
    >>> both = faces_nodes(mfs, 12)
    >>> all(np.array_equal(d, face_nodes(m, 12)[0]) for m, (d, _, _) in zip(mfs, both))
    True
    """
    out: list = [None] * len(faces)
    plans, batches = {}, {}
    for i, mf in enumerate(faces):
        if mf.natural:
            out[i] = face_nodes(mf, order)
            continue
        mu, eu = _direction_order(mf, 0, order)
        mv, ev = _direction_order(mf, 1, order)
        plan = plans[i] = _green_plan(mf, order, (mu, mv), (eu, ev))
        if plan.job is not None:
            size = (len(plan.job.br) - 1) * (len(plan.job.obr) - 1)
            key = plan.counts if size <= GRID_BATCH_FACE_CELLS else ("alone", i)
            batches.setdefault(key, []).append(i)
    grids = {}
    for key, members in batches.items():
        counts = plans[members[0]].counts
        for chunk in _grid_chunks(members, plans):
            grids.update(zip(chunk, grids_nodes([plans[i].job for i in chunk], counts)))
    for i, plan in plans.items():
        ders, w, exact = _green_nodes(faces[i], plan, grids.get(i))
        out[i] = _signed(faces[i], ders), w, exact
    return out


def _grid_chunks(members: list, plans: dict) -> list:
    """``members`` cut into runs whose padded cell count (faces × most inner spans × most
    outer spans) stays within ``GRID_BATCH_CELLS``."""
    chunks, chunk, most = [], [], (0, 0)
    for i in members:
        job = plans[i].job
        shape = (max(most[0], len(job.br) - 1), max(most[1], len(job.obr) - 1))
        if chunk and (len(chunk) + 1) * shape[0] * shape[1] > GRID_BATCH_CELLS:
            chunks.append(chunk)
            chunk, shape = [], (len(job.br) - 1, len(job.obr) - 1)
        chunk.append(i)
        most = shape
    chunks.append(chunk)
    return chunks
