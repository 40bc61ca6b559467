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
    p, knots, pts, w = rec["degree"], rec["knots"], rec["points"][:, :2], rec["weights"]
    n = len(pts)
    ctrl = pts if w is None else np.column_stack([pts * w[:, None], w])
    starts = np.unique(knots[p:n])  # span starts inside the domain (the last end excluded)
    starts = starts[starts < knots[n]]
    # expanded about each span's middle: |t - centre| <= h/2 keeps high degrees accurate
    centres = (starts + np.append(starts[1:], knots[n])) / 2
    ders = curve_derivatives(knots, p, ctrl, centres, p)
    fact = np.cumprod(np.concatenate([[1.0], np.arange(1.0, p + 1)]))
    return starts, centres, ders / fact[None, :, None]


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
        q = pcurve_d1(rec, t)
        ps.append(q[:, :2])
        ds.append(q[:, 2:])
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


def mass_face(face) -> MassFace:
    """A :class:`MassFace` for a face read back with :func:`surfmod.from_face`.

    >>> import surfmod as sm, build123d as bd
    >>> m = mass_face(sm.from_face(bd.Box(1, 1, 1).faces()[0]))
    >>> m.natural, m.degrees, m.plane
    (True, (1, 1), True)
    """
    from ..occ.pcurves import face_pcurves

    u0, u1, v0, v1 = bounds = tuple(b for r in face.domain for b in r)
    breaks = (_patch_breaks(face, u0, u1, 0, face.periods[0]), _patch_breaks(face, v0, v1, 1, face.periods[1]))
    surf = face.surface
    pcurves = face_pcurves(face.face_shape)
    wires = {rec["wire"] for rec in pcurves}
    natural = len(wires) == 1 and _on_box_border(pcurves, bounds)
    return MassFace(face._derivatives, bounds, breaks, -1.0 if face.reversed else 1.0,
                    (direction_degree(surf, 0), direction_degree(surf, 1)), None if natural else pcurves,
                    isinstance(surf, PlaneSurface))


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


def _largest_gap(mf: MassFace) -> float:
    """Largest distance, relative to the face box, from the end of an edge's p-curve to
    the nearest start of one (in the edges' directions in the face): 0 for a boundary
    whose p-curves join up."""
    u0, u1, v0, v1 = mf.bounds
    scale = np.array([max(u1 - u0, 1e-300), max(v1 - v0, 1e-300)])
    ends = []
    for rec in mf.pcurves:
        q = pcurve_d1(rec, np.array(rec["range"]))[:, :2] / scale
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
    s, other, ws = _inner_nodes(mf, k, m_in, P, wb)
    ders = mf.evaluate(s, other, 1) if k == 0 else mf.evaluate(other, s, 1)
    return ders, ws, exact and exacts[k]


def chebyshev_lobatto(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n >= 2`` Chebyshev–Lobatto points on ``[-1, 1]`` (descending) and their barycentric
    weights: interpolation there is well conditioned at any degree.

    >>> x, bw = chebyshev_lobatto(3)
    >>> x.round(12).tolist(), bw.tolist()
    [[1.0, 0.0, -1.0], [0.5, -1.0, 0.5]]
    """
    key = ("lobatto", n)
    if key not in _GAUSS:
        j = np.arange(n)
        bw = np.where(j % 2 == 0, 1.0, -1.0)
        bw[[0, -1]] *= 0.5
        _GAUSS[key] = (np.cos(np.pi * j / (n - 1)), bw)
    return _GAUSS[key]


def lagrange_values(y: np.ndarray, x: np.ndarray, bw: np.ndarray) -> np.ndarray:
    """``(N, K)``: the Lagrange basis of the points ``x`` (barycentric weights ``bw``) at
    ``y``, so that ``Σ_k L_k(y) f(x_k)`` is the interpolant of ``f`` (exact for
    polynomials of degree ``< K``).

    >>> x, bw = chebyshev_lobatto(4)
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


def _inner_nodes(mf: MassFace, k: int, m_in: int, P: np.ndarray, wb: np.ndarray):
    """Nodes ``(s, other, weights)`` of Green's inner integrals ``∫_{lo}^{P_k} g`` along
    direction ``k`` for the boundary nodes ``P`` (outer weights ``wb``).

    A node's inner integral is its partial span (the span's start to ``P_k``) plus the
    whole spans below it.  Where the surface is a polynomial of degree ``p`` along the
    outer direction, a whole span's integral is a polynomial of degree ``5p`` in the outer
    coordinate on each outer span, so it equals its interpolant at ``5p + 1``
    Chebyshev–Lobatto points there: the whole spans of all boundary nodes collapse onto
    those fixed points (weights summed through the Lagrange basis), instead of
    ``m_in`` nodes per whole span per boundary node."""
    x, w = gauss(m_in)
    br = mf.breaks[k]
    n_spans = len(br) - 1
    u = P[:, k]
    # spans wholly below each node (br[i + 1] <= u); the next one, when it starts below u, is partial
    full = np.searchsorted(br[1:], u, side="right")
    part = np.flatnonzero((full < n_spans) & (br[np.minimum(full, n_spans - 1)] < u))
    s_parts, o_parts, w_parts = [], [], []

    def add(a, b, other, weight):  # Gauss on [a, b] per row, at outer coordinate ``other``
        s_parts.append(((a + b)[:, None] / 2 + (b - a)[:, None] / 2 * x).ravel())
        w_parts.append(((b - a)[:, None] / 2 * w * weight[:, None]).ravel())
        o_parts.append(np.repeat(other, m_in))

    if part.size:
        add(br[full[part]], u[part], P[part, 1 - k], wb[part])
    p_out = mf.degrees[1 - k]
    obr = mf.breaks[1 - k]
    t = P[:, 1 - k]
    # the outer coordinate inside the face box (p-curves may reach a hair beyond it,
    # where the surface's next span may hold): those nodes keep their whole spans as nodes
    collapse = (full > 0) & (t >= obr[0]) & (t <= obr[-1])
    if p_out is not None and collapse.any():
        n_pts = 5 * p_out + 1
        q = np.clip(np.searchsorted(obr, t[collapse], side="right") - 1, 0, len(obr) - 2)
        # worth it when the fixed points are fewer than the whole spans they replace
        deepest = np.zeros(len(obr) - 1, int)
        np.maximum.at(deepest, q, full[collapse])
        if n_pts * deepest.sum() < np.sum(full[collapse]):
            xc, bw = chebyshev_lobatto(n_pts)
            a, b = obr[q], obr[q + 1]
            L = lagrange_values((2 * t[collapse] - a - b) / (b - a), xc, bw) * wb[collapse, None]
            acc = np.zeros((len(obr) - 1, n_spans + 1, n_pts))
            np.add.at(acc, (q, full[collapse]), L)
            # whole span i of a node counts where the node lies beyond it (full > i)
            W = np.cumsum(acc[:, ::-1], axis=1)[:, ::-1][:, 1:]  # (Q, S, K)
            qi, si, ki = np.nonzero(W)
            oa, ob = obr[qi], obr[qi + 1]
            add(br[si], br[si + 1], (oa + ob) / 2 + (ob - oa) / 2 * xc[ki], W[qi, si, ki])
            full = np.where(collapse, 0, full)
    rows = np.flatnonzero(full)
    if rows.size:  # whole spans node by node
        reps = full[rows]
        node = np.repeat(rows, reps)
        span = np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps)
        add(br[span], br[span + 1], P[node, 1 - k], wb[node])
    if not s_parts:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    return np.concatenate(s_parts), np.concatenate(o_parts), np.concatenate(w_parts)
