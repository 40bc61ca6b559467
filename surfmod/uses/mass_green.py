"""Quadrature nodes for the surface integrals of :mod:`surfmod.uses.mass`, face by face.

A face contributes ``∫∫_D g(u, v) du dv`` over its parameter region ``D`` for the
integrands ``g`` of the divergence theorem (``x·n``, ``x_i² n_i``, ``x_i³ n_i``, ...).
:func:`face_nodes` returns the surface partials at the nodes and their weights:

* a face whose boundary is its parameter rectangle: tensor Gauss–Legendre on every span;
* a trimmed face: Green's theorem, ``∫∫_D g = ∮ G dv`` with ``G = ∫_{u0}^{u} g du``
  (inner direction ``u``) or ``∫∫_D g = -∮ H du`` with ``H = ∫_{v0}^{v} g dv`` (inner
  direction ``v``): Gauss on the exact p-curves of the boundary (outer integral),
  and Gauss along the inner direction from the face box's edge to each boundary node.

The Gauss order is chosen per direction and per piece from what the integrand is.  On a
direction in which the surface is a polynomial of degree ``p`` (planes: 1; the axial
direction of cylinders, cones and extrusions: 1; a non-rational spline: its degree), the
integrands are polynomials of degree at most ``5p`` there (``x³`` times ``Su × Sv``),
which ``⌈(5p + 1)/2⌉`` Gauss nodes per span integrate exactly.  Green's inner integral
runs along the cheaper direction (fewer spans times nodes: the axis of a cylinder, not
its angle).  On a plane the inner integrals are polynomials of degree 4 in ``(u, v)``, so
a straight p-curve needs 3 nodes.  Everything else (angular directions, rational
splines, curved p-curves on curved faces) takes the caller's ``order`` per piece: eighth
turns on angular directions, knot spans, and at least ``PIECES`` pieces per curved edge.

Every p-curve is evaluated from data (:func:`surfmod.occ.pcurves.face_pcurves`): lines,
circles and B-splines for all nodes at once; other types through OCCT per node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..construct.curves import Line
from ..construct.elementary import PlaneSurface, ConicalSurface, CylindricalSurface
from ..construct.extrusion import TabulatedCylinder
from ..construct.revolution import RevolutionSurface
from ..eval.tensor import curve_derivatives
from ..nets.bspline import BSplineCurve, BSplineSurface
from .faces import _breaks, _patch_breaks, direction_breaks

#: curved p-curves are cut into at least this many pieces before Gauss
PIECES = 4
#: relative tolerance (to the box size) for "this p-curve lies on the face box's border"
RECTANGLE_RTOL = 1e-7

#: p-curves that meet within this (relative to the face box) at every vertex close the boundary
CLOSURE_RTOL = 1e-10

#: a Green grid serves boundary nodes up to this fraction of its outer span beyond it
GRID_REACH = 1e-3
#: the grid's own work (Lagrange and antiderivative weights, per-cell sums), in evaluated
#: nodes: below this saving node-by-node Gauss is faster
GRID_OVERHEAD = 1500

_GAUSS: dict = {}


def gauss(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on ``[-1, 1]`` (cached).

    >>> x, w = gauss(3)
    >>> round(float(w.sum()), 15), round(float((w * x**4).sum()), 15)
    (2.0, 0.4)
    """
    if order not in _GAUSS:
        _GAUSS[order] = np.polynomial.legendre.leggauss(order)
    return _GAUSS[order]


def exact_order(degree: int) -> int:
    """Gauss nodes per span that integrate the mass integrands exactly on a direction in
    which the surface is a polynomial of ``degree`` (integrand degree ``5 degree``).

    >>> exact_order(1), exact_order(3), exact_order(5)
    (3, 8, 13)
    """
    return (5 * degree + 2) // 2


def _curve_degree(curve):
    if isinstance(curve, Line):
        return 1
    if isinstance(curve, BSplineCurve) and curve.weights is None:
        return int(curve.degree)
    return None


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


def _spans(breaks: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = gauss(order)
    a, b = breaks[:-1, None], breaks[1:, None]
    return ((a + b) / 2 + (b - a) / 2 * x).ravel(), ((b - a) / 2 * w).ravel()


# -- p-curves ---------------------------------------------------------------------------------
def pcurve_d1(rec: dict, t: np.ndarray) -> np.ndarray:
    """``(N, 4)``: ``u, v, du/dt, dv/dt`` of a p-curve record at parameters ``t``."""
    from ..occ.pcurves import adaptor_d1

    kind = rec["kind"]
    t = np.asarray(t, dtype=float)
    out = np.empty((t.size, 4))
    if kind == "line":
        out[:, :2] = rec["origin"] + t[:, None] * rec["direction"]
        out[:, 2:] = rec["direction"]
    elif kind == "circle":
        c, s = np.cos(t)[:, None], np.sin(t)[:, None]
        r, x, y = rec["radius"], rec["x"], rec["y"]
        out[:, :2] = rec["centre"] + r * (c * x + s * y)
        out[:, 2:] = r * (c * y - s * x)
    elif kind == "bspline":
        if "taylor" not in rec:
            rec["taylor"] = _taylor_pieces(rec)
        starts, centres, coef = rec["taylor"]
        j = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)
        dt = (t - centres[j])[:, None]
        c = coef[j]  # (N, p+1, dim)
        val, der = c[:, -1], np.zeros_like(c[:, -1])
        for k in range(c.shape[1] - 2, -1, -1):  # Horner for the value and its derivative
            der = der * dt + val
            val = val * dt + c[:, k]
        if rec["weights"] is None:
            out[:, :2], out[:, 2:] = val, der
        else:
            out[:, :2] = val[:, :2] / val[:, 2:]
            out[:, 2:] = (der[:, :2] - out[:, :2] * der[:, 2:]) / val[:, 2:]
    else:
        out[:] = adaptor_d1(rec["adaptor"], t)
    return out


def _taylor_pieces(rec: dict):
    """A B-spline p-curve as one polynomial per knot span: ``(starts (S,), centres (S,),
    coefficients (S, p+1, dim))`` with ``C(t) = Σ_k c_k (t - centre)^k`` in homogeneous coordinates
    ``(w u, w v, w)`` (``(u, v)`` when polynomial).  Beyond the ends the first and last
    spans continue, as OCCT evaluates."""
    taylor_pieces([rec])
    return rec["taylor"]


def taylor_pieces(records: list) -> None:
    """Set ``rec["taylor"]`` (see :func:`_taylor_pieces`) on every B-spline p-curve record
    that lacks it, with one basis evaluation per degree for all of them: their knot
    vectors and control points are laid end to end, and each span's basis reads only its
    own curve's knots (``knots[span - p + 1 .. span + p]``), so one call serves all.

    >>> import build123d as bd
    >>> from surfmod.occ.pcurves import face_pcurves
    >>> recs = [r for r in face_pcurves(bd.Face(bd.Wire([bd.Spline((0, 0), (1, 1), (2, 0), (1, -1)),
    ...         bd.Edge.make_line((1, -1), (0, 0))])).wrapped) if r["kind"] == "bspline"]
    >>> taylor_pieces(recs); starts, centres, coef = recs[0]["taylor"]
    >>> coef.shape[1:] == (recs[0]["degree"] + 1, 2)
    True
    """
    from ..eval.basis import basis_derivatives, find_spans

    groups: dict = {}
    for rec in records:
        if rec["kind"] == "bspline" and "taylor" not in rec:
            groups.setdefault(rec["degree"], []).append(rec)
    for p, group in groups.items():
        knots, ctrl, spans, centres, firsts, counts = [], [], [], [], [], []
        k_off = c_off = 0
        for rec in group:
            k, pts, w = rec["knots"], rec["points"][:, :2], rec["weights"]
            n = len(pts)
            # homogeneous (w u, w v, w) for all; w = 1 leaves a polynomial curve's u, v as they are
            ones = np.ones(n) if w is None else w
            ctrl.append(np.column_stack([pts * ones[:, None], ones]))
            starts = np.unique(k[p:n])  # span starts inside the domain (the last end excluded)
            starts = starts[starts < k[n]]
            # expanded about each span's middle: |t - centre| <= h/2 keeps high degrees accurate
            mid = (starts + np.append(starts[1:], k[n])) / 2
            local = find_spans(k, p, n, mid)
            knots.append(k)
            spans.append(local + k_off)
            firsts.append(local - p + c_off)
            centres.append(mid)
            counts.append((starts, mid))
            k_off += len(k)
            c_off += n
        all_knots, all_ctrl = np.concatenate(knots), np.concatenate(ctrl)
        span, first, mid = np.concatenate(spans), np.concatenate(firsts), np.concatenate(centres)
        basis = basis_derivatives(all_knots, p, span, mid, p)  # (S, p+1 derivatives, p+1 functions)
        local_ctrl = all_ctrl[first[:, None] + np.arange(p + 1)]  # (S, p+1, 3)
        fact = np.cumprod(np.concatenate([[1.0], np.arange(1.0, p + 1)]))
        coef = np.einsum("skr,srd->skd", basis, local_ctrl) / fact[None, :, None]
        at = 0
        for rec, (starts, mid) in zip(group, counts):
            c = coef[at : at + len(starts)]
            at += len(starts)
            rec["taylor"] = (starts, mid, c if rec["weights"] is not None else np.ascontiguousarray(c[:, :, :2]))


def _crossings(rec: dict, cuts: np.ndarray, lines_u: np.ndarray, lines_v: np.ndarray, per_piece: int = 8) -> np.ndarray:
    """Parameters where a p-curve crosses the lines ``u = c`` and ``v = c``: exact on
    straight p-curves, else sign changes on one sampling refined by Newton steps (all
    crossings at once)."""
    if not len(lines_u) and not len(lines_v):
        return np.zeros(0)
    f, l = cuts[0], cuts[-1]
    coord = np.concatenate([np.zeros(len(lines_u), int), np.ones(len(lines_v), int)])
    lines = np.concatenate([lines_u, lines_v])
    if rec["kind"] == "line":
        d = rec["direction"][coord]
        ok = d != 0.0
        t = (lines[ok] - rec["origin"][coord[ok]]) / d[ok]
        return t[(t > f) & (t < l)]
    if rec["kind"] == "circle":
        # centre + r (cos t x + sin t y) = line: A cos t + B sin t = C, t = phi ± acos(C / R)
        r = rec["radius"]
        A, B, C = r * rec["x"][coord], r * rec["y"][coord], lines - rec["centre"][coord]
        R = np.hypot(A, B)
        ok = np.abs(C) < R
        phi, half = np.arctan2(B[ok], A[ok]), np.arccos(C[ok] / R[ok])
        base = np.concatenate([phi + half, phi - half])
        turns = np.arange(np.floor((f - base.max()) / (2 * np.pi)), np.ceil((l - base.min()) / (2 * np.pi)) + 1)
        t = (base[:, None] + 2 * np.pi * turns[None, :]).ravel()
        return t[(t > f) & (t < l)]
    a, b = cuts[:-1, None], cuts[1:, None]
    t = np.unique((a + (b - a) * np.linspace(0.0, 1.0, per_piece + 1)).ravel())
    s = pcurve_d1(rec, t)[:, coord] - lines[None, :]  # (T, L)
    i, j = np.nonzero(s[:-1] * s[1:] < 0)
    if not len(i):
        return np.zeros(0)
    lo, hi, c, cj = t[i], t[i + 1], lines[j], coord[j]
    x = lo + (hi - lo) * s[i, j] / (s[i, j] - s[i + 1, j])
    rows = np.arange(len(x))
    for _ in range(6):
        q = pcurve_d1(rec, x)
        d = q[rows, 2 + cj]
        step = np.divide(q[rows, cj] - c, d, out=np.zeros_like(x), where=d != 0.0)
        x = np.clip(x - step, lo, hi)
        if np.all(np.abs(step) <= 1e-15 * max(1.0, abs(l - f))):
            break
    return x


def _boundary(pcurves, outer_order, lines_u, lines_v):
    """Gauss nodes on every p-curve: ``(P (N, 2), dP (N, 2), weights (N,))`` with the
    weights signed by the edge's orientation in the face; ``outer_order(rec)`` is the
    Gauss order for a p-curve (``(order, exact)``)."""
    ps, ds, ws = [], [], []
    exact = True
    for rec in pcurves:
        f, l = rec["range"]
        if not l > f:
            continue
        m, ok = outer_order(rec)
        exact &= ok
        k = 1 if rec["kind"] == "line" else PIECES
        br = np.concatenate([rec["breaks"], np.linspace(f, l, k + 1)])
        br = np.unique(br[(br >= f) & (br <= l)])
        extra = _crossings(rec, br, lines_u, lines_v)
        if extra.size:
            br = np.unique(np.concatenate([br, extra]))
            br = br[np.concatenate([[True], np.diff(br) > 1e-13 * max(1.0, l - f)])]
        t, w = _spans(br, m)
        q = pcurve_d1(rec, np.concatenate([t, [f, l]]))
        rec["ends"] = q[-2:, :2]  # for _largest_gap, from the same call
        ps.append(q[:-2, :2])
        ds.append(q[:-2, 2:])
        ws.append(rec["sign"] * w)
    if not ps:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), exact
    return np.concatenate(ps), np.concatenate(ds), np.concatenate(ws), exact


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

    @property
    def natural(self) -> bool:
        return self.pcurves is None


def _on_box_border(pcurves, bounds) -> bool:
    u0, u1, v0, v1 = bounds
    tol = np.array([RECTANGLE_RTOL * max(1.0, u1 - u0), RECTANGLE_RTOL * max(1.0, v1 - v0)])
    sides = np.array([u0, u1, v0, v1])

    def on_sides(q):  # (N, 2) -> (N, 4): which border line each point lies on
        return np.abs(q[:, [0, 0, 1, 1]] - sides) <= tol[[0, 0, 1, 1]]

    lines = [rec for rec in pcurves if rec["kind"] == "line"]
    if lines:
        # a straight p-curve lies on the border iff both of its ends lie on one border line
        o = np.array([rec["origin"] for rec in lines])
        d = np.array([rec["direction"] for rec in lines])
        r = np.array([rec["range"] for rec in lines])
        first, last = on_sides(o + r[:, :1] * d), on_sides(o + r[:, 1:] * d)
        if not np.all(np.any(first & last, axis=1)):
            return False
    for rec in pcurves:
        if rec["kind"] != "line":
            f, l = rec["range"]
            q = pcurve_d1(rec, f + (l - f) * np.array([0.0, 0.137, 0.291, 0.5, 0.643, 0.871, 1.0]))
            if not on_sides(q[:, :2]).any(axis=1).all():
                return False
    return True


def mass_face(face, pcurves: list | None = None) -> MassFace:
    """A :class:`MassFace` for a face read back with :func:`surfmod.from_face` (``pcurves``:
    its :func:`~surfmod.occ.pcurves.face_pcurves`, when already read).

    >>> import surfmod as sm, build123d as bd
    >>> m = mass_face(sm.from_face(bd.Box(1, 1, 1).faces()[0]))
    >>> m.natural, m.degrees, m.plane
    (True, (1, 1), True)
    """
    from ..occ.pcurves import face_pcurves

    u0, u1, v0, v1 = bounds = tuple(b for r in face.domain for b in r)
    surf = face.surface
    plane = isinstance(surf, PlaneSurface)
    if plane:  # one polynomial piece each way
        breaks = (np.array([u0, u1]), np.array([v0, v1]))
    else:
        breaks = (_patch_breaks(face, u0, u1, 0, face.periods[0]), _patch_breaks(face, v0, v1, 1, face.periods[1]))
    if pcurves is None:
        pcurves = face_pcurves(face.face_shape)
        taylor_pieces(pcurves)
    natural = bool(pcurves) and all(rec["wire"] == 0 for rec in pcurves) and _on_box_border(pcurves, bounds)
    return MassFace(face._derivatives, bounds, breaks, -1.0 if face.reversed else 1.0,
                    (direction_degree(surf, 0), direction_degree(surf, 1)), None if natural else pcurves,
                    plane, (surf.origin, surf.x_dir, surf.y_dir) if plane else None)


def surface_mass_face(surf) -> MassFace:
    """A :class:`MassFace` for a closed surfmod surface over its whole domain."""
    breaks = []
    for direction, (lo, hi) in enumerate(surf.domain):
        b = direction_breaks(surf, direction)
        # analytic directions without knots: eight pieces keep Gauss converged
        breaks.append(_breaks(lo, hi, None, (hi - lo) / 8) if isinstance(b, str) or b is None else _breaks(lo, hi, b, None))
    (u0, u1), (v0, v1) = surf.domain
    return MassFace(surf._derivatives, (u0, u1, v0, v1), tuple(breaks), 1.0,
                    (direction_degree(surf, 0), direction_degree(surf, 1)), None, isinstance(surf, PlaneSurface))


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
    mu, eu = _direction_order(mf, 0, order)
    mv, ev = _direction_order(mf, 1, order)
    if mf.natural:
        un, uw = _spans(mf.breaks[0], mu)
        vn, vw = _spans(mf.breaks[1], mv)
        ders = mf.evaluate(np.repeat(un, vn.size), np.tile(vn, un.size), 1)
        w = np.outer(uw, vw).ravel()
        exact = eu and ev
    else:
        ders, w, exact = _green(mf, order, (mu, mv), (eu, ev))
    if mf.sign < 0:
        ders = ders.copy()
        ders[:, 1, 0] *= -1.0
    return ders, w, exact


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
    ends = []
    for rec in mf.pcurves:
        q = (rec["ends"] if "ends" in rec else pcurve_d1(rec, np.array(rec["range"]))[:, :2]) / scale
        ends.append(q if rec["sign"] > 0 else q[::-1])
    if not ends:
        return 0.0
    ends = np.array(ends)  # (E, 2 [start, end], 2)
    d = np.linalg.norm(ends[:, None, 1] - ends[None, :, 0], axis=-1)
    return float(d.min(axis=1).max())


def _green(mf: MassFace, order: int, orders, exacts):
    """Green's theorem nodes (see the module notes)."""
    def outer_order(rec):
        if mf.plane and rec["kind"] == "line":
            return 3, True  # G is a polynomial of degree 4 in (u, v), affine along the line
        return order, False

    lines = [mf.breaks[0][1:-1], mf.breaks[1][1:-1]]
    P, dP, wt, exact = _boundary(mf.pcurves, outer_order, lines[0], lines[1])
    # inner direction: the one with fewer inner nodes per boundary node, where the
    # p-curves close up.  Where they leave a gap (a model whose edges are off its faces)
    # the result depends on the direction, and BRepGProp's is u from the box's left edge.
    closed = _largest_gap(mf) <= CLOSURE_RTOL
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
    full, partial, q = _green_layout(mf, k, P)
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
        g = _grid_nodes(mf, k, (counts[0][0], counts[1][0]), P[on_grid], wb[on_grid], full[on_grid],
                        partial[on_grid], q[on_grid])
        rest = ~on_grid
        exact = exact and counts[0][1] and counts[1][1] and (exacts[k] or not rest.any())
    else:
        g, rest = (np.zeros(0),) * 3, np.ones(len(P), bool)
        exact = exact and exacts[k]
    n = _inner_nodes(mf, k, m_in, P[rest], wb[rest], full[rest], partial[rest])
    s, other, ws = (np.concatenate([a, b]) for a, b in zip(g, n))
    ders = mf.evaluate(s, other, 1) if k == 0 else mf.evaluate(other, s, 1)
    return ders, ws, exact


def chebyshev(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` Chebyshev points (first kind: inside ``(-1, 1)``, never on a span's end, where
    a degree-1 spline's derivatives jump), their barycentric weights, and the Chebyshev
    coefficients of their Lagrange basis, ``ℓ_j = Σ_m A[j, m] T_m`` (cached).
    Interpolation there is well conditioned at any degree.

    >>> x, bw, A = chebyshev(3)
    >>> x.round(12).tolist(), round(float(antiderivative_weights(np.array([1.0]), 3)[0] @ x**2), 14)
    ([0.866025403784, 0.0, -0.866025403784], 0.66666666666667)
    """
    key = ("chebyshev", n)
    if key not in _GAUSS:
        theta = (2 * np.arange(n) + 1) * np.pi / (2 * n)
        bw = np.where(np.arange(n) % 2 == 0, 1.0, -1.0) * np.sin(theta)
        # discrete orthogonality of T_m at these points: ℓ_j = (1/n) T_0 + (2/n) Σ_{m>0} T_m(x_j) T_m
        A = 2.0 / n * np.cos(np.outer(theta, np.arange(n)))
        A[:, 0] /= 2
        _GAUSS[key] = (np.cos(theta), bw, A)
        _GAUSS[("span integral", n)] = antiderivative_weights(np.ones(1), n)[0]
    return _GAUSS[key]


def antiderivative_weights(x1: np.ndarray, n: int) -> np.ndarray:
    """``(N, n)``: ``∫_{-1}^{x1} ℓ_j`` for the Lagrange basis ``ℓ_j`` of :func:`chebyshev`
    points, by the exact antiderivatives of the Chebyshev polynomials,
    ``∫ T_m = (T_{m+1}/(m+1) - T_{m-1}/(m-1)) / 2``."""
    _, _, A = chebyshev(n)
    theta = np.arccos(np.clip(x1, -1.0, 1.0))
    m = np.arange(n + 1)
    T = np.cos(np.outer(theta, m))  # (N, n + 1): T_0 .. T_n
    ends = np.where(m % 2 == 0, 1.0, -1.0)  # T_m(-1)
    I = np.empty((len(x1), n))
    I[:, 0] = T[:, 1] + 1.0
    if n > 1:
        I[:, 1] = (T[:, 2] - 1.0) / 4.0  # ∫ T_1 = x² / 2 = (T_2 + 1) / 4
    if n > 2:
        k = np.arange(2, n)
        I[:, 2:] = (T[:, 3:] / (k + 1) - T[:, 1:-2] / (k - 1)) / 2 - (ends[3:] / (k + 1) - ends[1:-2] / (k - 1)) / 2
    return I @ A.T


def lagrange_values(y: np.ndarray, x: np.ndarray, bw: np.ndarray) -> np.ndarray:
    """``(N, K)``: the Lagrange basis of the points ``x`` (barycentric weights ``bw``) at
    ``y``, so that ``Σ_k L_k(y) f(x_k)`` is the interpolant of ``f`` (exact for
    polynomials of degree ``< K``).

    >>> x, bw, _ = chebyshev(4)
    >>> L = lagrange_values(np.array([0.3, x[1]]), x, bw)
    >>> float(round(L[0] @ (x**3), 14)), L[1].round(15).tolist() == [0, 1, 0, 0]
    (0.027, True)
    """
    d = y[:, None] - x[None, :]
    hit = d == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = bw / d
        L = t / t.sum(axis=1, keepdims=True)
    rows = hit.any(axis=1)
    L[rows] = hit[rows]  # a value at an interpolation point is that point's value
    return L


def interpolation_points(degree, order: int) -> tuple[int, bool]:
    """Interpolation points per span along a direction for Green's grid
    (:func:`_grid_nodes`): ``5p + 1`` where the surface is a polynomial of degree ``p``
    (the integrands' degree: exact), else ``2 order`` (the polynomial degree Gauss of
    ``order`` integrates exactly).

    >>> interpolation_points(1, 12), interpolation_points(None, 12)
    ((6, True), (24, False))
    """
    if degree is not None and exact_order(degree) <= order:
        return 5 * degree + 1, True
    return 2 * order, False


def _green_layout(mf: MassFace, k: int, P: np.ndarray):
    """Per boundary node: the inner spans wholly below it (``full``), whether the next one
    is partial, and its outer span ``q``."""
    br, obr = mf.breaks[k], mf.breaks[1 - k]
    n_spans = len(br) - 1
    u = P[:, k]
    full = np.searchsorted(br[1:], u, side="right")  # br[i + 1] <= u
    partial = (full < n_spans) & (br[np.minimum(full, n_spans - 1)] < u)
    q = np.clip(np.searchsorted(obr, P[:, 1 - k], side="right") - 1, 0, len(obr) - 2)
    return full, partial, q


def _inner_nodes(mf: MassFace, k: int, m_in: int, P: np.ndarray, wb: np.ndarray, full, partial):
    """Nodes ``(s, other, weights)`` of Green's inner integrals ``∫_{lo}^{P_k} g`` along
    direction ``k`` node by node: Gauss of ``m_in`` on the partial span (its start to
    ``P_k``) and on every whole span below it."""
    x, w = gauss(m_in)
    br = mf.breaks[k]
    u, other = P[:, k], P[:, 1 - k]
    rows = np.flatnonzero(partial)
    reps = full
    node = np.concatenate([rows, np.repeat(np.arange(len(P)), reps)])
    start = np.concatenate([full[rows], np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps)])
    a = br[start]
    b = np.concatenate([u[rows], br[start[len(rows):] + 1]])
    s = ((a + b)[:, None] / 2 + (b - a)[:, None] / 2 * x).ravel()
    ws = ((b - a)[:, None] / 2 * w * wb[node, None]).ravel()
    return s, np.repeat(other[node], m_in), ws


def _sum_rows(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """``(n, ...)``: the rows of ``values`` summed by ``index`` (a sort and one
    ``add.reduceat``: ``np.add.at`` is many times slower)."""
    out = np.zeros((n,) + values.shape[1:])
    if len(index):
        order = np.argsort(index, kind="stable")
        idx = index[order]
        starts = np.flatnonzero(np.concatenate([[True], idx[1:] != idx[:-1]]))
        out[idx[starts]] = np.add.reduceat(values[order], starts, axis=0)
    return out


def _grid_nodes(mf: MassFace, k: int, counts, P: np.ndarray, wb: np.ndarray, full, partial, q):
    """Green's inner integrals of all boundary nodes on one fixed grid per cell (inner span
    × outer span): on each cell the integrands are replaced by their tensor interpolant at
    ``counts`` Chebyshev points (exact where the surface is a polynomial there, see
    :func:`interpolation_points`), whose inner antiderivative is integrated exactly.  Then

        Σ_n wb_n ∫_{lo}^{u_n} g(s, t_n) ds = Σ_cells Σ_jl Ω_jl g(s_j, t_l),

    ``Ω`` summing, over the boundary nodes, ``wb · L_l(t_n) · ∫ ℓ_j`` (over the whole
    spans below the node and the partial one): the surface is evaluated on the grids only,
    whatever the number of boundary nodes."""
    ks, kt = counts
    xs = chebyshev(ks)[0]
    xt, bwt, _ = chebyshev(kt)
    iws = _GAUSS[("span integral", ks)]  # ∫_{-1}^{1} ℓ_j
    br, obr = mf.breaks[k], mf.breaks[1 - k]
    n_spans, n_out = len(br) - 1, len(obr) - 1
    a, b = obr[q], obr[q + 1]
    lt = lagrange_values((2 * P[:, 1 - k] - a - b) / (b - a), xt, bwt) * wb[:, None]  # (N, kt)
    # whole spans: node n covers spans i < full_n; ∫ over a span of ℓ_j is h/2 · iws_j
    acc = _sum_rows(q * (n_spans + 1) + full, lt, n_out * (n_spans + 1)).reshape(n_out, n_spans + 1, kt)
    whole = np.cumsum(acc[:, ::-1], axis=1)[:, ::-1][:, 1:]  # (Q, S, kt): Σ over nodes with full > i
    h = np.diff(br)
    omega = (h / 2)[None, :, None, None] * iws[None, None, :, None] * whole[:, :, None, :]
    rows = np.flatnonzero(partial)
    if rows.size:
        # partial span f: ∫_{br_f}^{u_n} ℓ_j, exactly
        f = full[rows]
        x1 = (2 * P[rows, k] - br[f] - br[f + 1]) / h[f]  # in (-1, 1)
        c = antiderivative_weights(x1, ks) * (h[f] / 2)[:, None]  # (n, ks)
        cell = q[rows] * n_spans + f
        order = np.argsort(cell, kind="stable")
        cell, c, lp = cell[order], c[order], lt[rows[order]]
        cuts = np.flatnonzero(np.diff(cell)) + 1
        flat = omega.reshape(n_out * n_spans, ks, kt)
        for lo, hi in zip(np.concatenate([[0], cuts]), np.concatenate([cuts, [len(cell)]])):
            flat[cell[lo]] += c[lo:hi].T @ lp[lo:hi]  # Σ_n c_nj lt_nl, one product per cell
    qi, si = np.nonzero(np.any(omega != 0.0, axis=(2, 3)))
    s = ((br[si] + br[si + 1])[:, None] / 2 + (h[si] / 2)[:, None] * xs)  # (C, ks)
    t = ((obr[qi] + obr[qi + 1])[:, None] / 2 + ((obr[qi + 1] - obr[qi]) / 2)[:, None] * xt)  # (C, kt)
    shape = (len(qi), ks, kt)
    return (np.broadcast_to(s[:, :, None], shape).ravel(), np.broadcast_to(t[:, None, :], shape).ravel(),
            omega[qi, si].ravel())
