"""Filling 3-, 4- and 5-sided holes between surfaces with G1 or G2 (or G0) continuity.

The fill is a transfinite side-blending surface over a regular n-gon domain (Kato's
scheme): every side ``i`` carries a ribbon ``R_i(s, d) = C_i(s) + d T_i(s)``, the boundary
curve ``C_i`` of the neighbour and its cross-boundary derivative ``T_i`` pointing into the
hole (scaled by ``tension``), and the surface is ``sum_i B_i R_i(s_i, d_i)`` with ``d_i``
the distance to side ``i`` in the domain, ``s_i = d_(i-1) / (d_(i-1) + d_(i+1))`` and
weights ``B_i = prod_(j != i) d_j^2 / sum_k prod_(j != k) d_j^2``.  On side ``i`` the weight
``B_i`` is 1 and every weight has zero derivative, so the fill reproduces ``R_i`` to first
order there: same points, cross derivatives in the neighbour's tangent plane, i.e. G1
along every side whatever the corners do (no twist compatibility is needed).  For G2
the ribbons carry the second cross derivative too (``+ d^2/2 Q``, ``Q`` scaled by the
square of the tangent scale) and the weights use cubes, flat to second order on every
side: the fill then has the neighbour's 2-jet along each side, i.e. G2 there.

A four-sided hole is one patch over the square; a 3- or 5-sided hole is split from the
centre into n quadrilateral patches (vertex, side midpoints, centre) of the same smooth
surface, so they join each other smoothly.  Positions, first and second derivatives are
exact (second-order forward differentiation through the construction, vectorized); the
OCCT twin of each patch is a bicubic B-spline within ``tolerance`` (``exact_in_occt`` is
False; the cross-check is geometric).
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..errors import SurfmodError
from ..ops.continuity import SIDES, side_params
from ..surface import Surface


# -- second-order jets in the domain coordinates (x, y) -------------------------------------------
class Jet:
    """Value, gradient ``(N, 2, ...)`` and Hessian ``(N, 2, 2, ...)`` of a quantity."""

    __slots__ = ("v", "g", "h")

    def __init__(self, v, g, h):
        self.v, self.g, self.h = v, g, h

    def __add__(self, other):
        return Jet(self.v + other.v, self.g + other.g, self.h + other.h)

    def __sub__(self, other):
        return Jet(self.v - other.v, self.g - other.g, self.h - other.h)

    def scaled(self, c: float):
        return Jet(c * self.v, c * self.g, c * self.h)


def _tail(a, extra):
    return a.reshape(a.shape + (1,) * extra)


def mul(a: Jet, b: Jet) -> Jet:
    """Product of a scalar jet ``a`` with a scalar or vector jet ``b``."""
    k = b.v.ndim - 1
    av, ag, ah = _tail(a.v, k), _tail(a.g, k), _tail(a.h, k)
    v = av * b.v
    g = ag * b.v[:, None] + av[:, None] * b.g
    h = (ah * b.v[:, None, None] + ag[:, :, None] * b.g[:, None, :] + ag[:, None, :] * b.g[:, :, None]
         + av[:, None, None] * b.h)
    return Jet(v, g, h)


def reciprocal(a: Jet) -> Jet:
    v = 1.0 / a.v
    g = -a.g * (v * v)[:, None]
    h = -a.h * (v * v)[:, None, None] + 2.0 * a.g[:, :, None] * a.g[:, None, :] * (v**3)[:, None, None]
    return Jet(v, g, h)


def compose(c0, c1, c2, s: Jet) -> Jet:
    """``F(s)`` for a curve-valued ``F`` with ``F, F', F''`` given at ``s.v`` (each ``(N, 3)``)."""
    g = s.g[:, :, None] * c1[:, None, :]
    h = (s.g[:, :, None, None] * s.g[:, None, :, None]) * c2[:, None, None, :] + s.h[..., None] * c1[:, None, None, :]
    return Jet(c0, g, h)


# -- ribbons ----------------------------------------------------------------------------------------
class Ribbon:
    """Side ``i`` of the hole: ``C(s)`` and ``T(s)`` (with two derivatives) for s in [0, 1]."""

    def __init__(self, kind, source, side=None, reverse=False, scale=1.0, centre=None):
        self.kind, self.source, self.side, self.reverse = kind, source, side, reverse
        self.scale, self.centre = scale, centre
        self.second_order = False   # G2: the ribbon also carries the second cross derivative

    def _t(self, s):
        return 1.0 - s if self.reverse else s

    def curve(self, s):
        """``(C, C', C'', D, D', D'')`` at ``s``; ``D`` is the raw outward cross derivative."""
        sign = -1.0 if self.reverse else 1.0
        if self.kind == "curve":
            lo, hi = self.source.domain
            d = self.source.derivatives(lo + self._t(s) * (hi - lo), 2)
            rate = sign * (hi - lo)
            c = (d[:, 0], d[:, 1] * rate, d[:, 2] * rate**2)
            return c + (None, None, None)
        surf, side = self.source, self.side
        fixed, end = SIDES[side]
        lo, hi = surf.domain[1 - fixed]
        u, v = side_params(surf, side, lo + self._t(s) * (hi - lo))
        d = surf.derivatives(u, v, 3)
        rate = sign * (hi - lo)
        out = 1.0 if end == 1 else -1.0          # leaving the neighbour through its side
        if fixed == 0:   # side at fixed u: along = v, across = u
            c = (d[:, 0, 0], d[:, 0, 1] * rate, d[:, 0, 2] * rate**2)
            t = (out * d[:, 1, 0], out * d[:, 1, 1] * rate, out * d[:, 1, 2] * rate**2)
        else:
            c = (d[:, 0, 0], d[:, 1, 0] * rate, d[:, 2, 0] * rate**2)
            t = (out * d[:, 0, 1], out * d[:, 1, 1] * rate, out * d[:, 2, 1] * rate**2)
        return c + t

    def second(self, s):
        """``(Q, Q', Q'')``: the neighbour's second cross derivative along the side."""
        sign = -1.0 if self.reverse else 1.0
        surf, side = self.source, self.side
        fixed, _ = SIDES[side]
        lo, hi = surf.domain[1 - fixed]
        u, v = side_params(surf, side, lo + self._t(s) * (hi - lo))
        d = surf.derivatives(u, v, 4)
        rate = sign * (hi - lo)
        if fixed == 0:
            return d[:, 2, 0], d[:, 2, 1] * rate, d[:, 2, 2] * rate**2
        return d[:, 0, 2], d[:, 1, 2] * rate, d[:, 2, 2] * rate**2

    def jets(self, s: Jet, inradius: float):
        """Jets of ``C``, ``T`` and (second order ribbons, else None) ``Q`` at ``s``."""
        c0, c1, c2, d0, d1, d2 = self.curve(s.v)
        if d0 is None:  # G0: the ribbon heads for the centre of the hole
            d0, d1, d2 = (self.centre - c0) / inradius, -c1 / inradius, -c2 / inradius
            return compose(c0, c1, c2, s), compose(d0, d1, d2, s), None
        k = self.scale
        q = None
        if self.second_order:
            q0, q1, q2 = self.second(s.v)
            q = compose(k * k * q0, k * k * q1, k * k * q2, s)
        return compose(c0, c1, c2, s), compose(k * d0, k * d1, k * d2, s), q


# -- the n-gon domain and its side-blending surface -----------------------------------------------
def polygon(n: int):
    """Vertices ``(n, 2)`` of the regular n-gon with unit circumradius, inward side
    normals ``(n, 2)`` and the inradius."""
    ang = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    verts = np.stack([np.cos(ang), np.sin(ang)], 1)
    edge = np.roll(verts, -1, axis=0) - verts
    inward = np.stack([-edge[:, 1], edge[:, 0]], 1)
    inward /= np.linalg.norm(inward, axis=1, keepdims=True)
    return verts, inward, float(np.cos(np.pi / n))


def side_blend(ribbons, xy: np.ndarray, power: int = 2) -> Jet:
    """The fill and its first and second derivatives w.r.t. the domain point ``xy``;
    ``power`` 2 for G1 (weights flat to first order on every side), 3 for G2."""
    n = len(ribbons)
    verts, inward, r = polygon(n)
    N = len(xy)
    zero_h = np.zeros((N, 2, 2))
    dist = [Jet((xy - verts[i]) @ inward[i], np.broadcast_to(inward[i], (N, 2)).copy(), zero_h) for i in range(n)]
    sq = [mul(d, d) for d in dist]
    if power == 3:
        sq = [mul(d, q) for d, q in zip(dist, sq)]
    prods = []
    for i in range(n):
        p = None
        for j in range(n):
            if j != i:
                p = sq[j] if p is None else mul(p, sq[j])
        prods.append(p)
    total = prods[0]
    for p in prods[1:]:
        total = total + p
    inv_total = reciprocal(total)
    out = None
    for i, rib in enumerate(ribbons):
        prev, nxt = dist[(i - 1) % n], dist[(i + 1) % n]
        s = mul(prev, reciprocal(prev + nxt))
        c, t, q = rib.jets(s, r)
        value = c + mul(dist[i], t)
        if q is not None:
            value = value + mul(mul(dist[i], dist[i]), q).scaled(0.5)
        term = mul(mul(prods[i], inv_total), value)
        out = term if out is None else out + term
    return out


class FillPatch(Surface):
    """One quadrilateral piece of a fill: the unit square mapped bilinearly onto a quad
    of the n-gon domain, then through the side-blending surface (see the module doc)."""

    exact_in_occt = False
    occt_construct = "Geom_BSplineSurface (bicubic approximation)"

    def __init__(self, ribbons, quad, tolerance, matrix=None, power=2):
        self.ribbons, self.quad, self.tolerance = ribbons, np.asarray(quad, float), float(tolerance)
        self.power = power
        self.matrix = np.eye(4) if matrix is None else matrix
        self._occ = None
        self._corners = [np.asarray(rb.curve(np.array([0.0]))[0][0]) for rb in ribbons]

    @property
    def domain(self):
        return (0.0, 1.0), (0.0, 1.0)

    def _derivatives(self, u, v, order):
        if order > 2:
            raise SurfmodError(f"order: a fill patch provides derivatives up to order 2, got {order}")
        q00, q10, q01, q11 = self.quad
        xy = ((1 - u) * (1 - v))[:, None] * q00 + (u * (1 - v))[:, None] * q10 \
            + ((1 - u) * v)[:, None] * q01 + (u * v)[:, None] * q11
        verts, _, _ = polygon(len(self.ribbons))
        gap = np.linalg.norm(xy[:, None, :] - verts[None], axis=2)
        at_vertex = gap.min(axis=1) < 1e-9
        # the blend is 0/0 exactly at a polygon vertex: evaluate a hair inside, snap the point
        xy = np.where(at_vertex[:, None], xy * (1 - 1e-7), xy)
        jet = side_blend(self.ribbons, xy, self.power)
        xu = (1 - v)[:, None] * (q10 - q00) + v[:, None] * (q11 - q01)
        xv = (1 - u)[:, None] * (q01 - q00) + u[:, None] * (q11 - q10)
        xuv = np.broadcast_to(q00 - q10 - q01 + q11, xu.shape)
        out = np.zeros((len(u), order + 1, order + 1, 3))
        out[:, 0, 0] = jet.v
        if np.any(at_vertex):
            which = gap[at_vertex].argmin(axis=1)
            out[at_vertex, 0, 0] = np.array(self._corners)[which]
        if order >= 1:
            out[:, 1, 0] = np.einsum("nk,nki->ni", xu, jet.g)
            out[:, 0, 1] = np.einsum("nk,nki->ni", xv, jet.g)
        if order >= 2:
            out[:, 2, 0] = np.einsum("nk,nl,nkli->ni", xu, xu, jet.h)
            out[:, 0, 2] = np.einsum("nk,nl,nkli->ni", xv, xv, jet.h)
            out[:, 1, 1] = np.einsum("nk,nl,nkli->ni", xu, xv, jet.h) + np.einsum("nk,nki->ni", xuv, jet.g)
        m = self.matrix
        out = out @ m[:3, :3].T
        out[:, 0, 0] += m[:3, 3]
        return out

    def geom(self):
        if self._occ is None:
            from .offset import bicubic_approximation

            fit, _ = bicubic_approximation(self, np.linspace(0, 1, 9), np.linspace(0, 1, 9), self.tolerance)
            self._occ = fit.geom()
        return self._occ

    def transformed(self, matrix):
        return FillPatch(self.ribbons, self.quad, self.tolerance, transforms.affine(matrix) @ self.matrix, self.power)


class Fill(tuple):
    """The patches of a fill (one for a 4-sided hole, n for 3 and 5 sides), with
    ``n_sides`` and ``continuity``; ``faces()`` gives build123d faces."""

    n_sides: int
    continuity: str

    def faces(self):
        return [p.face() for p in self]


def _ribbon(item, index, order):
    from ..curve import Curve
    from .from_edge import as_curve

    if isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], Surface):
        surf, side = item
        if side not in SIDES:
            raise SurfmodError(f"boundary[{index}]: side must be one of u0, u1, v0, v1, got {side!r}")
        return Ribbon("surface", surf, side)
    if isinstance(item, Curve) or hasattr(item, "wrapped"):
        return Ribbon("curve", as_curve(item, f"boundary[{index}]"))
    raise SurfmodError(f"boundary[{index}]: expected (surface, side) or a curve/Edge, got {type(item).__name__}")


def fill(boundary, continuity: str = "G1", *, tension: float = 1.0, tolerance: float = 1e-4) -> Fill:
    """Fill the hole bounded by 3, 4 or 5 sides.  Each item of ``boundary`` is either
    ``(surface, side)`` (a side ``"u0"``, ``"u1"``, ``"v0"``, ``"v1"`` of a neighbour: the
    fill meets it with ``continuity``, ``"G0"``, ``"G1"`` or ``"G2"``) or a curve /
    build123d ``Edge`` (met with G0).
    The sides must close up end to end in the given order (either orientation each).
    ``tension`` scales the cross-boundary tangents; ``tolerance`` is for the OCCT
    B-spline twin of each patch.

    >>> import numpy as np, surfmod as sm
    >>> hole = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> sides = [(hole.translated(d), s) for d, s in
    ...          (((0, -1, 0), "v1"), ((1, 0, 0), "u0"), ((0, 1, 0), "v0"), ((-1, 0, 0), "u1"))]
    >>> f = sm.fill(sides)
    >>> len(f), bool(np.allclose(f[0].points(0.3, 0.6)[2], 0.0))
    (1, True)
    """
    if continuity not in ("G0", "G1", "G2"):
        raise SurfmodError(f"continuity: expected G0, G1 or G2, got {continuity!r}")
    if not isinstance(boundary, (list, tuple)) or not 3 <= len(boundary) <= 5:
        raise SurfmodError("boundary: expected a list of 3, 4 or 5 sides")
    tension = checks.positive(tension, "tension")
    tolerance = checks.positive(tolerance, "tolerance")
    ribbons = [_ribbon(item, i, continuity) for i, item in enumerate(boundary)]
    ends = []
    for rb in ribbons:
        c = rb.curve(np.array([0.0, 1.0]))[0]
        ends.append(c)
    size = max(float(np.ptp(np.concatenate(ends), axis=0).max()), 1e-300)
    tol = 1e-6 * size
    # orient every side to start where the previous one ends
    if min(np.linalg.norm(ends[0][1] - ends[1][k]) for k in (0, 1)) > min(
            np.linalg.norm(ends[0][0] - ends[1][k]) for k in (0, 1)):
        ribbons[0].reverse, ends[0] = True, ends[0][::-1]
    for i in range(1, len(ribbons)):
        if np.linalg.norm(ends[i][1] - ends[i - 1][1]) < np.linalg.norm(ends[i][0] - ends[i - 1][1]):
            ribbons[i].reverse, ends[i] = True, ends[i][::-1]
        if np.linalg.norm(ends[i][0] - ends[i - 1][1]) > tol:
            raise SurfmodError(f"boundary[{i}]: does not start where boundary[{i - 1}] ends "
                               f"(gap {np.linalg.norm(ends[i][0] - ends[i - 1][1]):.3g})")
    if np.linalg.norm(ends[0][0] - ends[-1][1]) > tol:
        raise SurfmodError("boundary: the last side does not end where the first begins")
    # ribbon scales: the tangent of length tension * (distance to the centre) / inradius
    s = np.linspace(0.0, 1.0, 17)
    samples = [rb.curve(s) for rb in ribbons]
    centre = np.concatenate([c[0] for c in samples]).mean(axis=0)
    n = len(ribbons)
    _, _, inradius = polygon(n)
    for rb, c in zip(ribbons, samples):
        rb.centre = centre
        if c[3] is not None:
            reach = float(np.linalg.norm(c[0] - centre, axis=1).mean())
            rb.scale = tension * reach / (inradius * max(float(np.linalg.norm(c[3], axis=1).mean()), 1e-300))
    if continuity == "G0":
        for rb in ribbons:
            rb.curve = _without_cross(rb.curve)
    verts, _, _ = polygon(n)
    if n == 4:
        quads = [(verts[0], verts[1], verts[3], verts[2])]
    else:
        mids = 0.5 * (verts + np.roll(verts, -1, axis=0))
        centre_xy = np.zeros(2)
        quads = [(verts[k], mids[k], mids[k - 1], centre_xy) for k in range(n)]
    if continuity == "G2":
        for rb in ribbons:
            rb.second_order = rb.kind == "surface"
    power = 3 if continuity == "G2" else 2
    out = Fill(FillPatch(ribbons, q, tolerance, power=power) for q in quads)
    out.n_sides, out.continuity = n, continuity
    return out


def _without_cross(curve_fn):
    """A ribbon curve function that drops the neighbour's cross derivative (G0 fill)."""

    def curve(s):
        c0, c1, c2, *_ = curve_fn(s)
        return c0, c1, c2, None, None, None

    return curve


def occt_fill(boundary, order: str = "G1"):
    """OCCT's ``BRepOffsetAPI_MakeFilling`` on the same hole: the neighbours' side edges
    with their faces as ``order`` constraints (curves as free C0 edges).  Returns the face."""
    from ..occ.filling import make_filling, nearest_edge

    constraints = []
    for i, item in enumerate(boundary):
        rb = _ribbon(item, i, "G1")
        if rb.kind == "curve":
            constraints.append((rb.source.edge(), None, "C0"))
            continue
        mid = rb.curve(np.array([0.5]))[0][0]
        face = rb.source.face()
        constraints.append((nearest_edge(face, mid), face, order))
    return make_filling(constraints)
