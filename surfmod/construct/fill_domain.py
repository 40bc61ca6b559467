"""The n-gon parameter domain of a fill and Kato's side-blending surface over it.

Quantities are carried as second-order jets in the domain coordinates ``(x, y)``
(value, gradient, Hessian), so the fill's first and second derivatives are exact and
vectorized: every operation below acts on all points at once.
"""

from __future__ import annotations

import numpy as np


class Jet:
    """Value ``(N, ...)``, gradient ``(N, 2, ...)`` and Hessian ``(N, 2, 2, ...)`` of a
    quantity over the domain.

    >>> import numpy as np
    >>> x = Jet(np.array([3.0]), np.array([[1.0, 0.0]]), np.zeros((1, 2, 2)))
    >>> sq = mul(x, x)
    >>> float(sq.v[0]), sq.g[0].tolist(), sq.h[0].tolist()
    (9.0, [6.0, 0.0], [[2.0, 0.0], [0.0, 0.0]])
    """

    __slots__ = ("g", "h", "v")

    def __init__(self, v, g, h):
        self.v, self.g, self.h = v, g, h

    def __add__(self, other):
        return Jet(self.v + other.v, self.g + other.g, self.h + other.h)

    def __sub__(self, other):
        return Jet(self.v - other.v, self.g - other.g, self.h - other.h)

    def scaled(self, c: float):
        return Jet(c * self.v, c * self.g, c * self.h)

    def rows(self, mask):
        return Jet(self.v[mask], self.g[mask], self.h[mask])


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
    """``1 / a`` for a scalar jet."""
    v = 1.0 / a.v
    g = -a.g * (v * v)[:, None]
    h = -a.h * (v * v)[:, None, None] + 2.0 * a.g[:, :, None] * a.g[:, None, :] * (v**3)[:, None, None]
    return Jet(v, g, h)


def compose(c0, c1, c2, s: Jet) -> Jet:
    """``F(s)`` for a curve-valued ``F`` with ``F, F', F''`` given at ``s.v`` (each ``(N, 3)``)."""
    g = s.g[:, :, None] * c1[:, None, :]
    h = (s.g[:, :, None, None] * s.g[:, None, :, None]) * c2[:, None, None, :] + s.h[..., None] * c1[:, None, None, :]
    return Jet(c0, g, h)


def polygon(n: int):
    """Vertices ``(n, 2)`` of the regular n-gon with unit circumradius (side ``i`` runs
    from vertex ``i`` to vertex ``i + 1``), inward side normals ``(n, 2)`` and the inradius.

    >>> verts, inward, r = polygon(4)
    >>> verts.shape, round(r, 12)
    ((4, 2), 0.707106781187)
    """
    ang = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    verts = np.stack([np.cos(ang), np.sin(ang)], 1)
    edge = np.roll(verts, -1, axis=0) - verts
    inward = np.stack([-edge[:, 1], edge[:, 0]], 1)
    inward /= np.linalg.norm(inward, axis=1, keepdims=True)
    return verts, inward, float(np.cos(np.pi / n))


def side_distances(n: int, xy: np.ndarray):
    """Jets of the distances ``d_i`` from the points ``xy`` to the n sides (affine)."""
    verts, inward, _ = polygon(n)
    count = len(xy)
    zero_h = np.zeros((count, 2, 2))
    return [Jet((xy - verts[i]) @ inward[i], np.broadcast_to(inward[i], (count, 2)).copy(), zero_h)
            for i in range(n)]


def side_parameter(dist, i: int) -> Jet:
    """``s_i = d_(i-1) / (d_(i-1) + d_(i+1))``: 0 at the start of side ``i``, 1 at its end."""
    n = len(dist)
    prev, nxt = dist[(i - 1) % n], dist[(i + 1) % n]
    return mul(prev, reciprocal(prev + nxt))


def ribbon_value(rib, dist, i: int, inradius: float) -> Jet:
    """Ribbon ``i`` as a function of the domain: ``C(s) + d T(s) + d^2/2 Q(s)``."""
    c, t, q = rib.jets(side_parameter(dist, i), inradius)
    value = c + mul(dist[i], t)
    if q is not None:
        value = value + mul(mul(dist[i], dist[i]), q).scaled(0.5)
    return value


def side_blend(ribbons, xy: np.ndarray, power: int = 2) -> Jet:
    """The fill and its first and second derivatives w.r.t. the domain point ``xy``:
    ``sum_i B_i R_i`` with ``B_i = prod_(j != i) d_j^p / sum_k prod_(j != k) d_j^p``;
    ``power`` p = 2 for G1 (weights flat to first order on every side), 3 for G2.

    At a polygon vertex every weight is 0/0; there the fill takes the 2-jet of the two
    ribbons meeting at that vertex (their mean).  Where the ribbons are corner compatible
    (see ``fill_ribbons.match_corners``) the two are equal and are the limit of the
    blend, so the fill is C2 through the vertex.
    """
    n = len(ribbons)
    verts, _, r = polygon(n)
    gap = np.linalg.norm(xy[:, None, :] - verts[None], axis=2)
    nearest = gap.argmin(axis=1)
    at_vertex = gap[np.arange(len(xy)), nearest] < 1e-9
    safe = np.where(at_vertex[:, None], 0.0, xy)       # vertex rows: filled in below
    dist = side_distances(n, safe)
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
        term = mul(mul(prods[i], inv_total), ribbon_value(rib, dist, i, r))
        out = term if out is None else out + term
    for k in np.unique(nearest[at_vertex]):
        rows = at_vertex & (nearest == k)
        vdist = side_distances(n, np.repeat(verts[k][None], rows.sum(), axis=0))
        before, after = (k - 1) % n, k        # side k-1 ends at vertex k, side k starts there
        mean = (ribbon_value(ribbons[before], vdist, before, r)
                + ribbon_value(ribbons[after], vdist, after, r)).scaled(0.5)
        out.v[rows], out.g[rows], out.h[rows] = mean.v, mean.g, mean.h
    return out
