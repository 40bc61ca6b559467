"""Ribbons of a fill and their corner compatibility: a neighbour's second-order Taylor
expansion across a side (:class:`Ribbon`), and :func:`match_corners`, which solves the
ribbons' free profiles so that two ribbons share their 1-jet (2-jet) at a corner, and
measures what cannot be matched (:class:`Corner`).
See :doc:`/guide/analysis` (section "How a blend and a fill are built").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SurfmodError
from ..sides import SIDES, side_params
from .fill_domain import compose, polygon, side_distances, side_parameter


def _quartic_basis():
    """Coefficients ``(5, 5)`` of the quartics ``b_k`` with ``b_k`` = 1 on the k-th of
    (value at 0, slope at 0, value at 1, slope at 1, value at 1/2) and 0 on the others."""
    rows = [[1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [1, 1, 1, 1, 1], [0, 1, 2, 3, 4], [1, .5, .25, .125, .0625]]
    return np.linalg.inv(np.array(rows, float))        # column k: monomial coefficients of b_k


_QUARTIC = _quartic_basis()


def _profile_basis(s):
    """The five end/middle basis quartics and their first and second derivatives at
    ``s``, each ``(5, N)``."""
    powers = np.stack([np.ones_like(s), s, s * s, s**3, s**4])
    d1 = np.stack([np.zeros_like(s), np.ones_like(s), 2 * s, 3 * s * s, 4 * s**3])
    d2 = np.stack([np.zeros_like(s), np.zeros_like(s), 2 * np.ones_like(s), 6 * s, 12 * s * s])
    return _QUARTIC.T @ powers, _QUARTIC.T @ d1, _QUARTIC.T @ d2


def _sprod(a, b):
    """Product of two scalar 1-D jets ``(f, f', f'')`` in ``s``."""
    return a[0] * b[0], a[1] * b[0] + a[0] * b[1], a[2] * b[0] + 2 * a[1] * b[1] + a[0] * b[2]


def _vprod(a, b):
    """Scalar 1-D jet times vector 1-D jet."""
    return (a[0][:, None] * b[0], a[1][:, None] * b[0] + a[0][:, None] * b[1],
            a[2][:, None] * b[0] + 2 * a[1][:, None] * b[1] + a[0][:, None] * b[2])


def _vsum(*jets):
    return tuple(sum(parts) for parts in zip(*jets))


class Ribbon:
    """Side of a hole: a neighbour's side (``kind`` ``"surface"``) or a free curve
    (``kind`` ``"curve"``, whose ribbon heads for the centre of the hole, G0)."""

    def __init__(self, kind, source, side=None, reverse=False):
        self.kind, self.source, self.side, self.reverse = kind, source, side, reverse
        self.scale, self.centre = 1.0, None
        self.order = 1            # cross derivatives carried: 0 (G0), 1 (G1), 2 (G2)
        # end data: (value at 0, slope at 0, value at 1, slope at 1)
        self.alpha = None
        self.beta = np.zeros(4)
        self.gamma = np.zeros(4)
        self.delta = np.zeros(4)

    def set_scale(self, k: float):
        self.scale = k
        self.alpha = np.array([k, 0.0, k, 0.0])

    def _t(self, s):
        return 1.0 - s if self.reverse else s

    def table(self, s, order: int = 4):
        """``F[:, k, m]`` = d^k/ds^k d^m/de^m of the neighbour at ``(s, 0)``, ``k + m <= order``."""
        sign = -1.0 if self.reverse else 1.0
        surf = self.source
        fixed, end = SIDES[self.side]
        lo, hi = surf.domain[1 - fixed]
        u, v = side_params(surf, self.side, lo + self._t(s) * (hi - lo))
        d = surf.derivatives(u, v, order)
        if fixed == 0:                       # side at fixed u: along = v, across = u
            d = np.swapaxes(d, 1, 2)
        rate = sign * (hi - lo)
        out = 1.0 if end == 1 else -1.0      # leaving the neighbour through its side
        k = np.arange(order + 1)
        return d * (rate ** k)[None, :, None, None] * (out ** k)[None, None, :, None]

    def curve(self, s):
        """``(C, C', C'')`` of the side at ``s``."""
        if self.kind == "curve":
            lo, hi = self.source.domain
            d = self.source.derivatives(lo + self._t(s) * (hi - lo), 2)
            rate = (-1.0 if self.reverse else 1.0) * (hi - lo)
            return d[:, 0], d[:, 1] * rate, d[:, 2] * rate**2
        f = self.table(s, 2)
        return f[:, 0, 0], f[:, 1, 0], f[:, 2, 0]

    def cross(self, s):
        """The neighbour's cross derivative ``F_e`` into the hole (``None`` for a curve)."""
        return None if self.kind == "curve" else self.table(s, 1)[:, 0, 1]

    def _profile(self, ends, s, middle=0.0):
        # the corner data at the ends, the default (tangent scale or 0) in the middle, so
        # that ``tension`` still shapes the fill away from the corners
        data = np.append(ends, middle)
        b, d1, d2 = _profile_basis(s)
        return data @ b, data @ d1, data @ d2

    def jets(self, s, inradius: float):
        """Domain jets of ``C``, ``T`` and (second-order ribbons, else None) ``Q`` at ``s``."""
        if self.kind == "curve" or self.order == 0:
            c0, c1, c2 = self.curve(s.v)
            d0, d1, d2 = (self.centre - c0) / inradius, -c1 / inradius, -c2 / inradius
            return compose(c0, c1, c2, s), compose(d0, d1, d2, s), None
        f = self.table(s.v, 2 + self.order)

        def fj(k, m):
            return f[:, k, m], f[:, k + 1, m], f[:, k + 2, m]

        alpha, beta = self._profile(self.alpha, s.v, self.scale), self._profile(self.beta, s.v)
        c = fj(0, 0)
        t = _vsum(_vprod(beta, fj(1, 0)), _vprod(alpha, fj(0, 1)))
        q = None
        if self.order == 2:
            gamma, delta = self._profile(self.gamma, s.v), self._profile(self.delta, s.v)
            two_ab = tuple(2 * x for x in _sprod(alpha, beta))
            qv = _vsum(_vprod(_sprod(beta, beta), fj(2, 0)), _vprod(two_ab, fj(1, 1)),
                       _vprod(_sprod(alpha, alpha), fj(0, 2)), _vprod(gamma, fj(1, 0)), _vprod(delta, fj(0, 1)))
            q = compose(*qv, s)
        return compose(*c, s), compose(*t, s), q


@dataclass(frozen=True)
class Corner:
    """Where ``boundary[index]`` ends and ``boundary[index + 1]`` begins: the ``point``,
    the neighbours' normal ``angle`` there (rad), their normal-curvature mismatch
    ``curvature`` (relative to the larger curvature there or 1/size of the hole) and the
    order ``matched`` by the ribbons: ``"G2"``/``"G1"`` (the fill is C2/C1 through the
    corner) or ``"none"`` (a free-curve side or incompatible neighbours: the fill meets
    each side with the asked continuity but is singular at the corner point itself).

    >>> Corner(0, np.zeros(3), 0.0, 0.0, "G2").matched
    'G2'
    """

    index: int
    point: np.ndarray
    angle: float
    curvature: float
    matched: str


def _in_plane(e1, e2, target):
    """``(x1, x2, residual)`` with ``x1 e1 + x2 e2`` the least-squares fit of ``target``."""
    a = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    x1, x2 = np.linalg.solve(a, [e1 @ target, e2 @ target])
    return x1, x2, target - x1 * e1 - x2 * e2


def _domain_corner(n: int, i: int):
    """At the vertex where side ``i`` ends and side ``j = i + 1`` starts: ``sigma_i``,
    ``sigma_j`` with ``grad s_i = sigma_i grad d_j`` and ``grad s_j = sigma_j grad d_i``,
    and the Hessians of ``s_i``, ``s_j`` as ``(a, b, c)`` in the basis
    ``gi gi^T, gi gj^T + gj gi^T, gj gj^T`` (``g`` = inward side normals)."""
    verts, inward, _ = polygon(n)
    j = (i + 1) % n
    dist = side_distances(n, verts[j][None])
    si, sj = side_parameter(dist, i), side_parameter(dist, j)
    gi, gj = inward[i], inward[j]
    basis = np.array([[gi[0] * gi[0], 2 * gi[0] * gj[0], gj[0] * gj[0]],
                      [gi[0] * gi[1], gi[0] * gj[1] + gj[0] * gi[1], gj[0] * gj[1]],
                      [gi[1] * gi[1], 2 * gi[1] * gj[1], gj[1] * gj[1]]])

    def split(h):
        return np.linalg.solve(basis, [h[0, 0], h[0, 1], h[1, 1]])

    return float(si.g[0] @ gj), float(sj.g[0] @ gi), split(si.h[0]), split(sj.h[0])


def _unit(x):
    return x / np.linalg.norm(x)


ANGLE_TOL = 1e-6       # rad: neighbours' normals at a corner this close count as one tangent plane
CURVATURE_TOL = 1e-6   # relative: curvatures this close count as equal (the G2 promise)


def match_corners(ribbons, order: int, size: float, angle_tol: float = ANGLE_TOL,
                  curvature_tol: float = CURVATURE_TOL):
    """Set the ribbons' end profiles so that neighbouring ribbons agree to ``order`` (1 or
    2) at every corner where two neighbour surfaces meet; returns a ``Corner`` per corner.
    A corner whose neighbours disagree beyond ``angle_tol`` (normals) keeps the default
    profiles; one that disagrees beyond ``curvature_tol`` (relative curvature) in a G2
    fill is matched in its tangential parts only and reported ``"G1"``."""
    n = len(ribbons)
    corners = []
    for i in range(n):
        j = (i + 1) % n
        ri, rj = ribbons[i], ribbons[j]
        point = ri.curve(np.array([1.0]))[0][0]
        if ri.kind == "curve" or rj.kind == "curve" or order == 0:
            corners.append(Corner(i, point, np.nan, np.nan, "none"))
            continue
        sig_i, sig_j, (ai, bi, ci), (aj, bj, cj) = _domain_corner(n, i)
        fi, fj = ri.table(np.array([1.0]), 2)[0], rj.table(np.array([0.0]), 2)[0]
        ni, nj = _unit(np.cross(fi[1, 0], fi[0, 1])), _unit(np.cross(fj[1, 0], fj[0, 1]))
        angle = float(np.arctan2(np.linalg.norm(np.cross(ni, nj)), ni @ nj))
        beta_i, alpha_i, _ = _in_plane(fi[1, 0], fi[0, 1], sig_j * fj[1, 0])
        beta_j, alpha_j, _ = _in_plane(fj[1, 0], fj[0, 1], sig_i * fi[1, 0])
        if angle > angle_tol or alpha_i <= 0 or alpha_j <= 0:
            corners.append(Corner(i, point, angle, np.nan, "none"))
            continue
        ri.alpha[2], ri.beta[2], rj.alpha[0], rj.beta[0] = alpha_i, beta_i, alpha_j, beta_j
        if order == 1:
            corners.append(Corner(i, point, angle, np.nan, "G1"))
            continue
        normal = _unit(ni + nj)
        ti, tj = sig_i * fi[1, 0], sig_j * fj[1, 0]     # the ribbons' domain-scaled cross tangents
        # twist: b C' + sigma T' must agree; T' = beta' F_s + alpha' F_e + beta F_ss + alpha F_se
        xi = bi * fi[1, 0] + sig_i * (beta_i * fi[2, 0] + alpha_i * fi[1, 1])
        xj = bj * fj[1, 0] + sig_j * (beta_j * fj[2, 0] + alpha_j * fj[1, 1])
        twist = abs((xi - xj) @ normal) / (np.linalg.norm(ti) * np.linalg.norm(tj))
        mean = 0.5 * (xi + xj)
        dbi, dai, _ = _in_plane(fi[1, 0], fi[0, 1], (mean - xi) / sig_i)
        dbj, daj, _ = _in_plane(fj[1, 0], fj[0, 1], (mean - xj) / sig_j)
        # second cross derivatives: Q_i(1) and Q_j(0) are fixed by the other side's curve
        want_i = sig_j**2 * fj[2, 0] + aj * fj[1, 0] - ai * fi[1, 0]
        base_i = beta_i**2 * fi[2, 0] + 2 * alpha_i * beta_i * fi[1, 1] + alpha_i**2 * fi[0, 2]
        gam_i, del_i, res_i = _in_plane(fi[1, 0], fi[0, 1], want_i - base_i)
        want_j = sig_i**2 * fi[2, 0] + ci * fi[1, 0] - cj * fj[1, 0]
        base_j = beta_j**2 * fj[2, 0] + 2 * alpha_j * beta_j * fj[1, 1] + alpha_j**2 * fj[0, 2]
        gam_j, del_j, res_j = _in_plane(fj[1, 0], fj[0, 1], want_j - base_j)
        jump = max(twist, np.linalg.norm(res_i) / (tj @ tj), np.linalg.norm(res_j) / (ti @ ti))
        bend = max(abs(fi[2, 0] @ ni) / (fi[1, 0] @ fi[1, 0]), abs(fi[0, 2] @ ni) / (fi[0, 1] @ fi[0, 1]),
                   abs(fj[2, 0] @ nj) / (fj[1, 0] @ fj[1, 0]), abs(fj[0, 2] @ nj) / (fj[0, 1] @ fj[0, 1]),
                   1.0 / size)
        rel = float(jump / bend)
        ri.alpha[3], ri.beta[3], rj.alpha[1], rj.beta[1] = dai, dbi, daj, dbj
        ri.gamma[2], ri.delta[2], rj.gamma[0], rj.delta[0] = gam_i, del_i, gam_j, del_j
        corners.append(Corner(i, point, angle, rel, "G2" if rel <= curvature_tol else "G1"))
    return corners


def check_corners(corners, continuity: str, allow_singular: bool, labels):
    """Raise, for a G1/G2 fill, when a corner between two neighbour surfaces cannot be
    matched to that order (unless ``allow_singular``)."""
    if allow_singular or continuity == "G0":
        return
    for c in corners:
        if np.isnan(c.angle):
            continue                      # a free-curve side: nothing to match
        a, b = labels[c.index], labels[(c.index + 1) % len(labels)]
        where = f"boundary[{a}] / boundary[{b}] corner at {np.round(c.point, 6).tolist()}"
        if c.matched == "none" and c.angle <= ANGLE_TOL:
            raise SurfmodError(f"boundary: the hole is not convex at the {where} (the next side leaves "
                               "backwards over the neighbour); split it into convex holes (or pass "
                               "allow_singular_corners=True to fill anyway, singular at that point)")
        if c.matched == "none":
            raise SurfmodError(f"boundary: the neighbours' tangent planes differ by {c.angle:.3g} rad at the "
                               f"{where}; a fill that is smooth at the corner cannot be {continuity} to both (pass "
                               "allow_singular_corners=True to fill anyway, singular at that point)")
        if continuity == "G2" and c.matched != "G2":
            raise SurfmodError(f"continuity: G2 is impossible at the {where}: the neighbours' normal "
                               f"curvatures there differ by {c.curvature:.3g} (relative); a fill that is "
                               "smooth at the corner cannot match both (use continuity='G1', or "
                               "allow_singular_corners=True for G2 along the sides with that point singular)")
