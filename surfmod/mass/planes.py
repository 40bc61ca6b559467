"""Stage five of the mass pipeline (:mod:`surfmod.mass`): trimmed planar faces in closed form
from the moments of their parameter regions (:func:`plane_moments`), one pass for all
planar faces of a part, no surface evaluated.

The inner integral starts at the face box's edge as in :mod:`surfmod.mass.nodes`, so a
boundary whose p-curves leave gaps gives the same result there and here.
See :doc:`/guide/uses` (section "How a face is integrated").
"""

from __future__ import annotations

import numpy as np

from .nodes import face_boundary, is_conic  # noqa: F401 (is_conic re-exported)
from .boundary import PIECE_FRACTIONS, PIECES  # noqa: F401
from .rules import gauss

# the six monomials a^p b^q (p + q <= 2) and, for the basis e = (1, a, b), the moment each
# product e_i e_j is (T2[i, j] = M[_SQUARE[i, j]]), likewise for one factor
_POWERS = [(p, q) for p in range(3) for q in range(3 - p)]
_INDEX = {pq: i for i, pq in enumerate(_POWERS)}


def _product_index(*axes: int) -> int:
    return _INDEX[(axes.count(1), axes.count(2))]


_SQUARE = np.array([[_product_index(i, j) for j in range(3)] for i in range(3)])
_LINE = np.array([_product_index(i) for i in range(3)])


def _region_moments(faces: list, foot: np.ndarray, order: int):
    """Per face: the six moments ``M_pq`` (rows of ``(F, 6)``, oriented so that the area
    is positive) about its ``foot`` ``(uc, vc)``, and whether every boundary rule was exact."""
    parts, owners, exact = [], [], np.ones(len(faces), bool)
    lines, arcs = [], []  # of the faces bounded by lines and circles, all at once
    for i, mf in enumerate(faces):
        if is_conic(mf):
            lines.extend((i, rec) for rec in mf.pcurves if rec["kind"] == "line")
            arcs.extend((i, rec) for rec in mf.pcurves if rec["kind"] == "circle")
            continue
        # 3 Gauss nodes per straight piece: the integrands are of degree 3 along it, exact
        P, dP, wt, exact[i] = face_boundary(mf, order)
        parts.append((P, wt * dP[:, 1]))
        owners.append(np.full(len(wt), i))
    if lines:  # 3 Gauss nodes each, as boundaries() lays them
        P, dP, wt, owner = _line_nodes(lines)
        parts.append((P, wt * dP[:, 1]))
        owners.append(owner)
    if arcs:  # Gauss on equal pieces, as boundaries() lays them (not exact: order matters)
        P, wb, owner = _arc_nodes(arcs, order)
        parts.append((P, wb))
        owners.append(owner)
        exact[np.unique(owner)] = False
    moments = np.zeros((len(faces), len(_POWERS)))
    owner = np.concatenate(owners) if owners else np.zeros(0, int)
    if len(owner):
        order_ = np.argsort(owner, kind="stable")  # face by face, each face's nodes in order
        owner = owner[order_]
        P, wb = np.concatenate([p for p, _ in parts])[order_], np.concatenate([w for _, w in parts])[order_]
        count = np.bincount(owner, minlength=len(faces))
        u0 = np.array([mf.bounds[0] for mf in faces])[owner]
        A, B, b = P[:, 0] - foot[owner, 0], u0 - foot[owner, 0], P[:, 1] - foot[owner, 1]
        d = P[:, 0] - u0
        # ∫_{u0}^{u} (s - uc)^p ds = (A^(p+1) - B^(p+1)) / (p + 1) = d Σ_k A^k B^(p-k) / (p + 1)
        sums = [np.ones_like(A)]
        for p in range(1, 3):
            sums.append(sums[-1] * B + A**p)  # Σ_{k=0}^{p} A^k B^(p-k), Horner in B
        inner = [wb * d * sums[p] / (p + 1) for p in range(3)]
        b_pow = [np.ones_like(b), b, b * b]
        values = np.stack([inner[p] * b_pow[q] for p, q in _POWERS], axis=1)  # (N, 6)
        starts = np.concatenate([[0], np.cumsum(count)[:-1]])
        live = count > 0
        moments[live] = np.add.reduceat(values, starts[live], axis=0)
    moments[moments[:, 0] < 0] *= -1.0  # boundary traversed clockwise in (u, v)
    return moments, exact


def _line_nodes(lines: list):
    """``(P, dP, weights, owner)``: 3 Gauss nodes on each straight p-curve of ``lines``
    (``(owner, record)`` pairs), the values :func:`surfmod.mass.boundary.boundaries`
    gives a line on a plane (one piece, its ends; the weights signed by the edge's
    orientation)."""
    live = [rec for _, rec in lines if rec["range"][1] > rec["range"][0]]
    owner = np.repeat([i for i, rec in lines if rec["range"][1] > rec["range"][0]], 3).astype(int)
    if not live:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), owner
    x, gw = gauss(3)
    data = np.array([(*rec["range"], rec["sign"]) for rec in live])
    a, b, sign = data[:, :1], data[:, 1:2], data[:, 2:]
    t = ((a + b) / 2 + (b - a) / 2 * x).ravel()
    w = (sign * ((b - a) / 2 * gw)).ravel()
    origin = np.repeat(np.array([rec["origin"] for rec in live]), 3, axis=0)
    direction = np.repeat(np.array([rec["direction"] for rec in live]), 3, axis=0)
    return origin + t[:, None] * direction, direction, w, owner


def _arc_nodes(arcs: list, order: int):
    """``(P, dP_v · weights, owner)``: the Gauss nodes
    :func:`surfmod.mass.boundary.boundaries` lays on circular p-curves of a plane
    (``arcs``: ``(owner, record)`` pairs): ``order`` nodes on each of ``PIECES`` equal
    pieces of the range, ``P(t) = C + r (cos t X + sin t Y)``, the weights signed by the
    edge's orientation and multiplied by ``dv/dt``."""
    data = np.array([(*rec["range"], rec["sign"], rec["radius"], *rec["centre"], *rec["x"], *rec["y"]) for _, rec in arcs])
    f, l, sign, r = data[:, :1], data[:, 1:2], data[:, 2:3], data[:, 3:4]
    centre, ax, ay = data[:, 4:6], data[:, 6:8], data[:, 8:10]
    live = (l > f)[:, 0]
    cuts = f + (l - f) * PIECE_FRACTIONS
    cuts[:, -1] = l[:, 0]  # the end itself, as np.linspace gives it
    a, b = cuts[:, :-1, None], cuts[:, 1:, None]  # (A, PIECES, 1)
    x, gw = gauss(order)
    t = ((a + b) / 2 + (b - a) / 2 * x).reshape(len(arcs), -1)  # (A, PIECES order)
    w = sign * ((b - a) / 2 * gw).reshape(len(arcs), -1)
    c, s_ = np.cos(t)[:, :, None], np.sin(t)[:, :, None]
    rr = r[:, :, None]
    P = centre[:, None, :] + rr * (c * ax[:, None, :] + s_ * ay[:, None, :])
    dv = (rr * (c * ay[:, None, :] - s_ * ax[:, None, :]))[:, :, 1]
    owner = np.repeat(np.array([i for i, _ in arcs], int), t.shape[1])
    keep = np.repeat(live, t.shape[1])  # an empty range has no nodes
    return P.reshape(-1, 2)[keep], (w * dv).ravel()[keep], owner[keep]


def plane_moments(faces: list, order: int, ref) -> tuple[np.ndarray, np.ndarray]:
    """``(F, 14)`` ``[area, V, M(3), S(3, 3)]`` of trimmed planar faces (each a
    :class:`~surfmod.mass.nodes.MassFace` with its frame), the sums
    :func:`surfmod.mass.moments.node_moments` makes of their quadrature nodes, in closed form
    from the moments of their parameter regions (module notes); and per face whether no
    rule depended on ``order`` (straight p-curves only).

    >>> import surfmod as sm, build123d as bd
    >>> from surfmod.mass.nodes import mass_face
    >>> disc = mass_face(sm.from_face(bd.Face(bd.Wire.make_circle(2.0))))
    >>> m, exact = plane_moments([disc], 12, np.zeros(3))
    >>> bool(abs(m[0, 0] - 4 * np.pi) < 1e-13), bool(exact[0])
    (True, False)
    """
    ref = np.asarray(ref, dtype=float)
    origin, ex, ey = (np.array([mf.frame[i] for mf in faces]) for i in range(3))
    # the foot of the reference point on each plane, in its parameters (X, Y orthonormal)
    foot = np.stack([np.sum((ref - origin) * ex, axis=1), np.sum((ref - origin) * ey, axis=1)], axis=1)
    M, exact = _region_moments(faces, foot, order)
    c = origin + foot[:, :1] * ex + foot[:, 1:] * ey - ref  # x = c + a X + b Y
    frame = np.stack([c, ex, ey], axis=2)  # (F, 3 coordinates, 3 basis functions)
    sign = np.array([mf.sign for mf in faces])
    n = sign[:, None] * np.cross(ex, ey)
    T1, T2 = M[:, _LINE], M[:, _SQUARE]
    X1 = (frame @ T1[:, :, None])[:, :, 0]  # ∫ x_i
    X2 = frame @ T2 @ frame.transpose(0, 2, 1)  # ∫ x_i x_j = Σ_pq F_ip F_jq T2_pq
    # x·n is constant on a plane (the height of the reference point above it): each
    # radial integrand x_i x_j (x·n) is that height times a moment of the region
    height = np.sum(n * c, axis=1)
    out = np.empty((len(faces), 14))
    out[:, 0] = np.linalg.norm(np.cross(ex, ey), axis=1) * M[:, 0]
    out[:, 1] = height * M[:, 0] / 3.0
    out[:, 2:5] = height[:, None] * X1 / 4.0
    out[:, 5:] = (height[:, None, None] * X2).reshape(len(faces), 9) / 5.0
    return out, exact
