"""Textbook evaluators written plainly, one point at a time: the yardstick for the fast code.

Nothing here is vectorized or clever; each function follows the formula as printed in
the lecture / The NURBS Book so that a disagreement points at the fast path.
"""

from __future__ import annotations

from math import comb

import numpy as np


def bernstein(i: int, n: int, t: float) -> float:
    """B_{i,n}(t) = C(n, i) t^i (1 - t)^(n - i)."""
    return comb(n, i) * t**i * (1.0 - t) ** (n - i)


def bezier_point(net, s: float, t: float, weights=None) -> np.ndarray:
    """Sum_i Sum_j B_i(s) B_j(t) w_ij P_ij / Sum w B B."""
    net = np.asarray(net, dtype=float)
    n, m = net.shape[0] - 1, net.shape[1] - 1
    w = np.ones(net.shape[:2]) if weights is None else np.asarray(weights, dtype=float)
    num, den = np.zeros(3), 0.0
    for i in range(n + 1):
        for j in range(m + 1):
            b = bernstein(i, n, s) * bernstein(j, m, t) * w[i, j]
            num += b * net[i, j]
            den += b
    return num / den


def cox_de_boor(i: int, p: int, knots, t: float) -> float:
    """Recursive N_{i,p}(t) on half-open spans [k_i, k_{i+1}) (0/0 taken as 0)."""
    if p == 0:
        return 1.0 if knots[i] <= t < knots[i + 1] else 0.0
    out = 0.0
    d1 = knots[i + p] - knots[i]
    if d1 > 0:
        out += (t - knots[i]) / d1 * cox_de_boor(i, p - 1, knots, t)
    d2 = knots[i + p + 1] - knots[i + 1]
    if d2 > 0:
        out += (knots[i + p + 1] - t) / d2 * cox_de_boor(i + 1, p - 1, knots, t)
    return out


def bspline_basis(knots, p: int, n_ctrl: int, t: float) -> np.ndarray:
    """All N_{i,p}(t), i < n_ctrl.  At the right end of the domain the half-open spans
    give nothing, so the limit from the left is taken by mirroring: N_i(t) on knots k
    is N_{n-1-i}(-t) on the reversed, negated knots, where -t is the domain start."""
    knots = [float(k) for k in knots]
    if t >= knots[n_ctrl]:
        mirrored = [-k for k in reversed(knots)]
        return np.array([cox_de_boor(i, p, mirrored, -t) for i in range(n_ctrl)])[::-1]
    return np.array([cox_de_boor(i, p, knots, t) for i in range(n_ctrl)])


def bspline_surface_point(net, p, q, ku, kv, u, v, weights=None) -> np.ndarray:
    net = np.asarray(net, dtype=float)
    n, m = net.shape[:2]
    w = np.ones((n, m)) if weights is None else np.asarray(weights, dtype=float)
    bu = bspline_basis(ku, p, n, u)
    bv = bspline_basis(kv, q, m, v)
    coef = np.outer(bu, bv) * w
    return np.einsum("ij,ijk->k", coef, net) / coef.sum()


def cox_de_boor_derivative(i: int, p: int, knots, t: float, k: int) -> float:
    """k-th derivative of N_{i,p} by the textbook formula applied k times:
    N'_{i,p} = p N_{i,p-1} / (u_{i+p} - u_i) - p N_{i+1,p-1} / (u_{i+p+1} - u_{i+1})
    (terms with a zero denominator dropped; half-open spans: the right-hand derivative)."""
    if k == 0:
        return cox_de_boor(i, p, knots, t)
    if k > p:
        return 0.0
    out = 0.0
    d1 = knots[i + p] - knots[i]
    if d1 > 0:
        out += p / d1 * cox_de_boor_derivative(i, p - 1, knots, t, k - 1)
    d2 = knots[i + p + 1] - knots[i + 1]
    if d2 > 0:
        out -= p / d2 * cox_de_boor_derivative(i + 1, p - 1, knots, t, k - 1)
    return out


def bspline_basis_derivative(knots, p: int, n_ctrl: int, t: float, k: int) -> np.ndarray:
    """All d^k N_{i,p}(t), i < n_ctrl; at the right end of the domain the left-hand limit,
    by mirroring as in :func:`bspline_basis` (a k-th derivative changes sign k times)."""
    knots = [float(x) for x in knots]
    if t >= knots[n_ctrl]:
        mirrored = [-x for x in reversed(knots)]
        vals = [cox_de_boor_derivative(i, p, mirrored, -t, k) for i in range(n_ctrl)]
        return (-1) ** k * np.array(vals)[::-1]
    return np.array([cox_de_boor_derivative(i, p, knots, t, k) for i in range(n_ctrl)])


def bspline_surface_derivatives(net, p, q, ku, kv, u, v, order: int, weights=None) -> np.ndarray:
    """Mixed partials ``[k, l, :]`` for k, l <= order at one point.  Polynomial: the double
    sum of basis derivatives times the poles.  Rational: the same sums for the weighted
    poles A and the weights W, then the quotient rule written out,
    S^(k,l) = (A^(k,l) - sum_{(i,j) != (0,0), i<=k, j<=l} C(k,i) C(l,j) W^(i,j) S^(k-i,l-j)) / W."""
    net = np.asarray(net, dtype=float)
    n, m = net.shape[:2]
    w = np.ones((n, m)) if weights is None else np.asarray(weights, dtype=float)
    bu = [bspline_basis_derivative(ku, p, n, u, k) for k in range(order + 1)]
    bv = [bspline_basis_derivative(kv, q, m, v, k) for k in range(order + 1)]
    a = np.array([[np.einsum("i,j,ij,ijd->d", bu[k], bv[l], w, net) for l in range(order + 1)] for k in range(order + 1)])
    ww = np.array([[np.einsum("i,j,ij->", bu[k], bv[l], w) for l in range(order + 1)] for k in range(order + 1)])
    s = np.zeros_like(a)
    for k in range(order + 1):
        for l in range(order + 1):
            acc = a[k, l].copy()
            for i in range(k + 1):
                for j in range(l + 1):
                    if i or j:
                        acc -= comb(k, i) * comb(l, j) * ww[i, j] * s[k - i, l - j]
            s[k, l] = acc / ww[0, 0]
    return s


def curvatures_from_partials(d) -> tuple[float, float]:
    """Gaussian and mean curvature from partials ``d[k, l]`` (k + l <= 2) by the
    fundamental forms, normal n = Su x Sv / |Su x Sv|:
    K = (L N - M^2) / (E G - F^2), H = (E N - 2 F M + G L) / (2 (E G - F^2))."""
    su, sv, suu, suv, svv = d[1, 0], d[0, 1], d[2, 0], d[1, 1], d[0, 2]
    n = np.cross(su, sv)
    n = n / np.linalg.norm(n)
    e, f, g = su @ su, su @ sv, sv @ sv
    l_, m_, n_ = suu @ n, suv @ n, svv @ n
    det = e * g - f * f
    return (l_ * n_ - m_ * m_) / det, (e * n_ - 2 * f * m_ + g * l_) / (2 * det)


#: The lecture's uniform cubic B-spline matrix (times 1/6), rows for [t^3 t^2 t 1].
UNIFORM_CUBIC_M = np.array([[-1.0, 3.0, -3.0, 1.0], [3.0, -6.0, 3.0, 0.0], [-3.0, 0.0, 3.0, 0.0], [1.0, 4.0, 1.0, 0.0]]) / 6.0

#: The lecture's Hermite matrix, rows for [t^3 t^2 t 1].
HERMITE_M = np.array([[2.0, -2.0, 1.0, 1.0], [-3.0, 3.0, -2.0, -1.0], [0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])


def uniform_cubic_point(net, u: float, v: float) -> np.ndarray:
    """Lecture matrix form on patch (i, j) = (floor u, floor v):
    [s^3 s^2 s 1] M P_ij M^T [t^3 t^2 t 1]^T with P_ij the 4x4 neighbourhood."""
    net = np.asarray(net, dtype=float)
    n, m = net.shape[:2]
    i = min(int(np.floor(u)), n - 4)
    j = min(int(np.floor(v)), m - 4)
    s, t = u - i, v - j
    S = np.array([s**3, s**2, s, 1.0])
    T = np.array([t**3, t**2, t, 1.0])
    P = net[i : i + 4, j : j + 4]
    return np.einsum("a,ab,bck,dc,d->k", S, UNIFORM_CUBIC_M, P, UNIFORM_CUBIC_M, T)


def hermite_point(corners, du, dv, twist, s: float, t: float) -> np.ndarray:
    """Lecture form S(s, t) = S M B M^T T^T with the 4x4 geometry matrix B."""
    B = np.empty((4, 4, 3))
    B[0, 0], B[0, 1], B[1, 0], B[1, 1] = corners[0, 0], corners[0, 1], corners[1, 0], corners[1, 1]
    B[0, 2], B[0, 3], B[1, 2], B[1, 3] = dv[0, 0], dv[0, 1], dv[1, 0], dv[1, 1]
    B[2, 0], B[2, 1], B[3, 0], B[3, 1] = du[0, 0], du[0, 1], du[1, 0], du[1, 1]
    B[2, 2], B[2, 3], B[3, 2], B[3, 3] = twist[0, 0], twist[0, 1], twist[1, 0], twist[1, 1]
    S = np.array([s**3, s**2, s, 1.0])
    T = np.array([t**3, t**2, t, 1.0])
    return np.einsum("a,ab,bck,dc,d->k", S, HERMITE_M, B, HERMITE_M, T)


def finite_difference(fn, x: float, h: float = 1e-6) -> np.ndarray:
    """Central difference of a vector function of one variable."""
    return (np.asarray(fn(x + h)) - np.asarray(fn(x - h))) / (2 * h)


def span_quadrature(s, integrand, n: int = 32) -> float:
    """Tensor Gauss-Legendre quadrature of ``integrand(ders)`` over the domain of ``s``,
    one ``n x n`` rule per knot-span rectangle (independent of OCCT); ``ders`` are the
    first-order grid derivatives ``(n, n, 2, 2, 3)`` of one rectangle."""
    x, w = np.polynomial.legendre.leggauss(n)
    (u0, u1), (v0, v1) = s.domain
    knots = getattr(s, "knots", None)
    bu = np.unique(np.clip(knots[0], u0, u1)) if knots is not None else np.array([u0, u1])
    bv = np.unique(np.clip(knots[1], v0, v1)) if knots is not None else np.array([v0, v1])
    total = 0.0
    for a, b in zip(bu[:-1], bu[1:]):
        for c, d in zip(bv[:-1], bv[1:]):
            ders = s.grid_derivatives((x + 1) / 2 * (b - a) + a, (x + 1) / 2 * (d - c) + c, 1)
            total += np.einsum("i,j,ij", w, w, integrand(ders)) * (b - a) * (d - c) / 4
    return total


def surface_area(s, n: int = 32) -> float:
    """Area: the integral of ``|Su x Sv|``."""
    return span_quadrature(s, lambda d: np.linalg.norm(np.cross(d[:, :, 1, 0], d[:, :, 0, 1]), axis=-1), n)


def enclosed_volume(s, n: int = 32) -> float:
    """Volume enclosed by a closed surface, by the divergence theorem: (1/3) |int S . (Su x Sv)|."""
    flux = span_quadrature(s, lambda d: np.einsum("ijk,ijk->ij", d[:, :, 0, 0], np.cross(d[:, :, 1, 0], d[:, :, 0, 1])), n)
    return abs(flux) / 3.0
