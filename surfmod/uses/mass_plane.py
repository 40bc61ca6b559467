"""Trimmed planar faces in closed form: their mass integrals from boundary integrals alone.

On a plane ``S = O + u X + v Y`` every integrand of :mod:`surfmod.uses.mass` is a
polynomial of degree at most 3 in ``(u, v)`` (``x_i² x_j n_i`` with ``x`` affine and ``n``
constant), so a face's share is fixed by the ten moments ``M_pq = ∫∫_D a^p b^q`` of its
parameter region ``D`` (``p + q ≤ 3``, ``a, b`` the parameters shifted to the foot of the
reference point: no cancellation).  Green's theorem turns each into a boundary integral
with the inner antiderivative written out,

    M_pq = ∮ [∫_{u0}^{u} (s - uc)^p ds] b^q dv,

the inner integral from the face box's edge ``u0`` exactly as the node-by-node rule of
:mod:`surfmod.uses.mass_green` takes it (so a boundary whose p-curves leave gaps gives the
same result as there), evaluated as ``(u - u0) Σ A^k B^(p-k) / (p + 1)`` without
cancellation.  The outer integral runs on the same Gauss nodes of the p-curves
(:func:`surfmod.uses.mass_boundary.boundaries`: 3 per straight piece, exact); on faces
bounded by lines and circles only (plates with holes, slots) the circular arcs are
integrated in closed form instead: along an arc every integrand is a trigonometric
polynomial of degree at most 5, integrated term by term (:func:`_conic_moments`), so such
faces need no boundary pass at all.  Then with
``x = c + a X + b Y`` the sums are tensor contractions of the moments with ``[c, X, Y]``:
no surface is evaluated and no inner node is made, one pass for all planar faces of a
part.
"""

from __future__ import annotations

from math import comb

import numpy as np

from .mass_green import face_boundary
from .mass_grid import gauss

# the ten monomials a^p b^q (p + q <= 3) and, for the basis e = (1, a, b), the moment each
# product e_i e_j e_k is (T3[i, j, k] = M[_CUBE[i, j, k]]), likewise for fewer factors
_POWERS = [(p, q) for p in range(4) for q in range(4 - p)]
_INDEX = {pq: i for i, pq in enumerate(_POWERS)}


def _product_index(*axes: int) -> int:
    return _INDEX[(axes.count(1), axes.count(2))]


_CUBE = np.array([[[_product_index(i, j, k) for k in range(3)] for j in range(3)] for i in range(3)])
_SQUARE = np.array([[_product_index(i, j) for j in range(3)] for i in range(3)])
_LINE = np.array([_product_index(i) for i in range(3)])


def is_conic(mf) -> bool:
    """Whether a trimmed planar face is bounded by straight and circular p-curves only
    (holes, slots, rounded pockets): its region moments are then found in closed form
    (:func:`_conic_moments`), without Gauss nodes on its circles.

    >>> import surfmod as sm, build123d as bd
    >>> from surfmod.uses.mass_green import mass_face
    >>> is_conic(mass_face(sm.from_face(bd.Face(bd.Wire.make_circle(2.0)))))
    True
    """
    return bool(mf.plane and not mf.natural and mf.pcurves
                and all(rec["kind"] in ("line", "circle") for rec in mf.pcurves))


def _region_moments(faces: list, foot: np.ndarray, order: int):
    """Per face: the ten moments ``M_pq`` (rows of ``(F, 10)``, oriented so that the area
    is positive) about its ``foot`` ``(uc, vc)``, and whether every boundary rule was exact."""
    parts, exact = [], np.ones(len(faces), bool)
    conic = [i for i, mf in enumerate(faces) if is_conic(mf)]
    arcs = []
    for i, mf in enumerate(faces):
        if i in conic:
            # its lines by 3 Gauss nodes (as boundaries() lays them), its arcs in closed form
            P, dP, wt = _line_nodes([rec for rec in mf.pcurves if rec["kind"] == "line"])
            arcs.extend((i, rec) for rec in mf.pcurves if rec["kind"] == "circle")
        else:
            # 3 Gauss nodes per straight piece: the integrands are of degree 4 along it, exact
            P, dP, wt, exact[i] = face_boundary(mf, order)
        parts.append((P, wt * dP[:, 1]))
    count = np.array([len(w) for _, w in parts])
    moments = np.zeros((len(faces), len(_POWERS)))
    u0_face = np.array([mf.bounds[0] for mf in faces])
    if count.sum():
        P, wb = np.concatenate([p for p, _ in parts]), np.concatenate([w for _, w in parts])
        owner = np.repeat(np.arange(len(faces)), count)
        u0 = u0_face[owner]
        A, B, b = P[:, 0] - foot[owner, 0], u0 - foot[owner, 0], P[:, 1] - foot[owner, 1]
        d = P[:, 0] - u0
        # ∫_{u0}^{u} (s - uc)^p ds = (A^(p+1) - B^(p+1)) / (p + 1) = d Σ_k A^k B^(p-k) / (p + 1)
        sums = [np.ones_like(A)]
        for p in range(1, 4):
            sums.append(sums[-1] * B + A**p)  # Σ_{k=0}^{p} A^k B^(p-k), Horner in B
        inner = [wb * d * sums[p] / (p + 1) for p in range(4)]
        b_pow = [np.ones_like(b), b, b * b, b * b * b]
        values = np.stack([inner[p] * b_pow[q] for p, q in _POWERS], axis=1)  # (N, 10)
        starts = np.concatenate([[0], np.cumsum(count)[:-1]])
        live = count > 0
        moments[live] = np.add.reduceat(values, starts[live], axis=0)
    if arcs:
        owner = np.array([i for i, _ in arcs])
        np.add.at(moments, owner, _conic_moments([rec for _, rec in arcs], foot[owner], u0_face[owner]))
    moments[moments[:, 0] < 0] *= -1.0  # boundary traversed clockwise in (u, v)
    return moments, exact


def _line_nodes(lines: list):
    """``(P, dP, weights)``: 3 Gauss nodes on each straight p-curve, the values
    :func:`surfmod.uses.mass_boundary.boundaries` gives a line on a plane (one piece, its
    ends; the weights signed by the edge's orientation)."""
    live = [rec for rec in lines if rec["range"][1] > rec["range"][0]]
    if not live:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)
    x, gw = gauss(3)
    data = np.array([(*rec["range"], rec["sign"]) for rec in live])
    a, b, sign = data[:, :1], data[:, 1:2], data[:, 2:]
    t = ((a + b) / 2 + (b - a) / 2 * x).ravel()
    w = (sign * ((b - a) / 2 * gw)).ravel()
    origin = np.repeat(np.array([rec["origin"] for rec in live]), 3, axis=0)
    direction = np.repeat(np.array([rec["direction"] for rec in live]), 3, axis=0)
    return origin + t[:, None] * direction, direction, w


# -- circular arcs in closed form ------------------------------------------------------------
# a trigonometric polynomial Σ_k c_k e^{ikt}, |k| <= 5, as complex coefficients (n, 11),
# column k + 5: the moment integrands along an arc are products of at most five factors
# of degree 1 (a + b cos t + c sin t), integrated exactly term by term
_TOP = 5


def _trig(a0, a1, a2) -> np.ndarray:
    """``a0 + a1 cos t + a2 sin t`` as coefficients: ``c_0 = a0``, ``c_±1 = (a1 ∓ i a2) / 2``."""
    out = np.zeros((len(a0), 2 * _TOP + 1), complex)
    out[:, _TOP] = a0
    out[:, _TOP + 1] = (a1 - 1j * a2) / 2
    out[:, _TOP - 1] = (a1 + 1j * a2) / 2
    return out


def _times(poly: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """``poly · factor`` for a factor of degree 1 (the product keeps degree <= 5)."""
    out = poly * factor[:, _TOP, None]
    out[:, 1:] += poly[:, :-1] * factor[:, _TOP + 1, None]
    out[:, :-1] += poly[:, 1:] * factor[:, _TOP - 1, None]
    return out


def _integral(poly: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """``∫_{t0}^{t1}`` of each row, exactly: ``c_0 Δ + Σ c_k e^{ik t_m} 2 sin(k Δ/2) / k``
    (about the arc's middle ``t_m``: no cancellation on short arcs)."""
    k = np.arange(-_TOP, _TOP + 1)
    half, mid = (t1 - t0)[:, None] / 2, ((t0 + t1) / 2)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        weight = np.where(k == 0, 2 * half, 2 * np.sin(k * half) / np.where(k == 0, 1, k)) * np.exp(1j * k * mid)
    return np.real(np.sum(poly * weight, axis=1))


def _conic_moments(arcs: list, foot: np.ndarray, u0: np.ndarray) -> np.ndarray:
    """``(n, 10)``: each circular p-curve's share ``∮ [∫_{u0}^{u} (s - uc)^p ds] (v - vc)^q dv``
    of the region moments (signed by its orientation), exactly: along ``P(t) = C + r (cos t
    X + sin t Y)`` the inner integral is ``Σ_j binom(p+1, j) B^(p+1-j) δ^j / (p + 1)`` with
    ``δ = u - u0`` and ``B = u0 - uc`` (no cancellation near ``u0``), a trigonometric
    polynomial, and so is ``(v - vc)^q dv/dt``."""
    c = np.array([rec["centre"] for rec in arcs])
    x = np.array([rec["x"] for rec in arcs])
    y = np.array([rec["y"] for rec in arcs])
    r = np.array([rec["radius"] for rec in arcs])
    t0, t1 = np.array([rec["range"] for rec in arcs]).T
    sign = np.array([rec["sign"] for rec in arcs])
    B = u0 - foot[:, 0]
    delta = _trig(c[:, 0] - u0, r * x[:, 0], r * y[:, 0])  # u - u0
    beta = _trig(c[:, 1] - foot[:, 1], r * x[:, 1], r * y[:, 1])  # v - vc
    dv = _trig(np.zeros(len(arcs)), r * y[:, 1], -r * x[:, 1])  # dv/dt
    delta_pow = [None, delta]
    for j in range(2, 5):
        delta_pow.append(_times(delta_pow[-1], delta))
    out = np.zeros((len(arcs), len(_POWERS)))
    for p in range(4):
        # (A^(p+1) - B^(p+1)) / (p + 1) with A = B + δ, times dv/dt
        inner = sum(comb(p + 1, j) * B[:, None] ** (p + 1 - j) * delta_pow[j] for j in range(1, p + 2)) / (p + 1)
        term = _times(inner, dv)
        for q in range(4 - p):
            out[:, _INDEX[(p, q)]] = _integral(term, t0, t1)
            term = _times(term, beta)
    return sign[:, None] * out


def plane_moments(faces: list, order: int, ref) -> tuple[np.ndarray, np.ndarray]:
    """``(F, 14)`` ``[area, V, M(3), S(3, 3)]`` of trimmed planar faces (each a
    :class:`~surfmod.uses.mass_green.MassFace` with its frame), the sums
    :func:`surfmod.uses.mass._moments` makes of their quadrature nodes, in closed form
    from the moments of their parameter regions (module notes); and per face whether no
    rule depended on ``order`` (straight and circular p-curves only: circles are integrated
    in closed form, :func:`_conic_moments`).

    >>> import surfmod as sm, build123d as bd
    >>> from surfmod.uses.mass_green import mass_face
    >>> disc = mass_face(sm.from_face(bd.Face(bd.Wire.make_circle(2.0))))
    >>> m, exact = plane_moments([disc], 12, np.zeros(3))
    >>> bool(abs(m[0, 0] - 4 * np.pi) < 1e-14), bool(exact[0])
    (True, True)
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
    T1, T2, T3 = M[:, _LINE], M[:, _SQUARE], M[:, _CUBE]
    X1 = (frame @ T1[:, :, None])[:, :, 0]  # ∫ x_i
    X2 = np.sum((frame @ T2) * frame, axis=2)  # ∫ x_i² = Σ_pq F_ip F_iq T2_pq
    # ∫ x_i² x_j = Σ_pqr F_ip F_iq F_jr T3_pqr, as three batched products
    Y = T3 @ frame.transpose(0, 2, 1)[:, None]  # (F, p, q, j)
    Z = (frame @ Y.reshape(len(faces), 3, 9)).reshape(len(faces), 3, 3, 3)  # (F, i, q, j)
    X3 = np.sum(frame[:, :, :, None] * Z, axis=2)  # (F, i, j)
    out = np.empty((len(faces), 14))
    out[:, 0] = np.linalg.norm(np.cross(ex, ey), axis=1) * M[:, 0]
    out[:, 1] = np.sum(n * X1, axis=1) / 3.0
    out[:, 2:5] = n * X2 / 2.0
    m = n[:, :, None] * X3  # Σ w x_i² n_i x_j
    second = (m + m.transpose(0, 2, 1)) / 4.0
    idx = np.arange(3)
    second[:, idx, idx] = n * X3[:, idx, idx] / 3.0
    out[:, 5:] = second.reshape(len(faces), 9)
    return out, exact
