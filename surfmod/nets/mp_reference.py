"""Curvatures of a (rational) B-spline surface in high precision, straight from its net:
the independent judge when surfmod and OCCT disagree on curvature.

Nothing here shares code with the evaluators it judges: the basis functions and their
derivatives come from the Cox–de Boor recursion in ``mpmath`` at ``dps`` decimal digits,
the rational quotient rule is written out on the homogeneous partials, and the
curvatures follow from the two fundamental forms.  One point costs a few milliseconds, so
it settles the worst few samples of a face, not the face.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np


def _span(knots, p: int, n: int, t):
    """The span ``i`` with ``knots[i] <= t < knots[i + 1]`` (the last non-empty span at the
    end, the end spans beyond the knot range), as surfmod and OCCT choose at a knot."""
    if t >= knots[n]:
        i = n - 1
        while i > p and knots[i] >= knots[i + 1]:
            i -= 1
        return i
    if t < knots[p]:
        return p
    lo, hi = p, n
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if knots[mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo


def _basis_ders(knots, p: int, i: int, t, order: int):
    """``ders[k][j] = d^k N_{i-p+j,p}(t)`` for ``k <= order`` (The NURBS Book, A2.3), in mpf."""
    left, right = [mp.mpf(0)] * (p + 1), [mp.mpf(0)] * (p + 1)
    ndu = [[mp.mpf(0)] * (p + 1) for _ in range(p + 1)]
    ndu[0][0] = mp.mpf(1)
    for j in range(1, p + 1):
        left[j] = t - knots[i + 1 - j]
        right[j] = knots[i + j] - t
        saved = mp.mpf(0)
        for r in range(j):
            ndu[j][r] = right[r + 1] + left[j - r]
            temp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j][j] = saved
    ders = [[mp.mpf(0)] * (p + 1) for _ in range(order + 1)]
    for j in range(p + 1):
        ders[0][j] = ndu[j][p]
    for r in range(p + 1):
        s1, s2 = 0, 1
        a = [[mp.mpf(0)] * (p + 1) for _ in range(2)]
        a[0][0] = mp.mpf(1)
        for k in range(1, order + 1):
            d = mp.mpf(0)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk]
                d = a[s2][0] * ndu[rk][pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j]
                d += a[s2][j] * ndu[rk + j][pk]
            if r <= pk:
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r]
                d += a[s2][k] * ndu[r][pk]
            ders[k][r] = d
            s1, s2 = s2, s1
    factor = p
    for k in range(1, order + 1):
        for j in range(p + 1):
            ders[k][j] *= factor
        factor *= p - k
    return ders


def mp_partials(control_points, weights, degree, knots, u: float, v: float, dps: int = 40):
    """``d[k][l]`` (``k + l <= 2``): the partials of the surface at ``(u, v)`` as mpf 3-vectors."""
    with mp.workdps(dps):
        net = np.asarray(control_points, dtype=float)
        w = np.ones(net.shape[:2]) if weights is None else np.asarray(weights, dtype=float)
        (p, q), (ku, kv) = degree, knots
        ku, kv = [mp.mpf(float(x)) for x in ku], [mp.mpf(float(x)) for x in kv]
        n, m = net.shape[:2]
        uu, vv = mp.mpf(float(u)), mp.mpf(float(v))
        i, j = _span(ku, p, n, uu), _span(kv, q, m, vv)
        bu, bv = _basis_ders(ku, p, i, uu, 2), _basis_ders(kv, q, j, vv, 2)
        # homogeneous partials A (x w, y w, z w) and W
        hom = {}
        for k in range(3):
            for l in range(3 - k):
                a, wt = [mp.mpf(0)] * 3, mp.mpf(0)
                for r in range(p + 1):
                    for s in range(q + 1):
                        b = bu[k][r] * bv[l][s]
                        if b == 0:
                            continue
                        ww = mp.mpf(float(w[i - p + r, j - q + s]))
                        for c in range(3):
                            a[c] += b * ww * mp.mpf(float(net[i - p + r, j - q + s, c]))
                        wt += b * ww
                hom[k, l] = (a, wt)
        # quotient rule S = A / W, order by order
        d = {}
        w0 = hom[0, 0][1]
        for k in range(3):
            for l in range(3 - k):
                val = list(hom[k, l][0])
                for a_ in range(k + 1):
                    for b_ in range(l + 1):
                        if a_ == 0 and b_ == 0:
                            continue
                        coef = mp.binomial(k, a_) * mp.binomial(l, b_) * hom[a_, b_][1]
                        for c in range(3):
                            val[c] -= coef * d[k - a_, l - b_][c]
                d[k, l] = [x / w0 for x in val]
        return d


def curve_partials(points, weights, degree: int, knots, t: float, dps: int = 40):
    """``d[k]`` (``k <= 2``): position, first and second derivative of the curve at ``t``
    as mpf 3-vectors (the quotient rule on the homogeneous derivatives when weighted)."""
    with mp.workdps(dps):
        pts = np.asarray(points, dtype=float)
        w = np.ones(len(pts)) if weights is None else np.asarray(weights, dtype=float)
        k = [mp.mpf(float(x)) for x in knots]
        tt = mp.mpf(float(t))
        i = _span(k, degree, len(pts), tt)
        b = _basis_ders(k, degree, i, tt, 2)
        hom = []
        for order in range(3):
            a, wt = [mp.mpf(0)] * 3, mp.mpf(0)
            for r in range(degree + 1):
                ww = mp.mpf(float(w[i - degree + r])) * b[order][r]
                wt += ww
                for c in range(3):
                    a[c] += ww * mp.mpf(float(pts[i - degree + r, c]))
            hom.append((a, wt))
        d = []
        for order in range(3):
            val = list(hom[order][0])
            for j in range(1, order + 1):
                coef = mp.binomial(order, j) * hom[j][1]
                val = [x - coef * y for x, y in zip(val, d[order - j])]
            d.append([x / hom[0][1] for x in val])
        return d


def mp_curvatures(control_points, weights, degree, knots, u: float, v: float, dps: int = 40):
    """``(gaussian, mean, k1, k2)`` at ``(u, v)`` against the normal ``Su x Sv``, as floats.

    >>> import numpy as np
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3] / 2.0
    >>> net[..., 2] = (net[..., 0] - 0.5) ** 2   # z = x^2 / 2 - x / 2 + 1/4: a parabolic cylinder
    >>> k = mp_curvatures(net, None, (2, 2), ([0, 0, 0, 1, 1, 1],) * 2, 0.5, 0.5)
    >>> [round(x, 12) for x in k]                 # z'' = 1 at its vertex: k1 = 1
    [0.0, 0.5, 1.0, 0.0]
    """
    with mp.workdps(dps):
        d = mp_partials(control_points, weights, degree, knots, u, v, dps)
        su, sv = d[1, 0], d[0, 1]
        cross = [su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2], su[0] * sv[1] - su[1] * sv[0]]
        norm = mp.sqrt(sum(x * x for x in cross))
        nrm = [x / norm for x in cross]
        dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
        e, f, g = dot(su, su), dot(su, sv), dot(sv, sv)
        l_, m_, n_ = dot(d[2, 0], nrm), dot(d[1, 1], nrm), dot(d[0, 2], nrm)
        det = e * g - f * f
        gauss = (l_ * n_ - m_ * m_) / det
        mean = (e * n_ - 2 * f * m_ + g * l_) / (2 * det)
        disc = mp.sqrt(max(mean * mean - gauss, mp.mpf(0)))
        return float(gauss), float(mean), float(mean + disc), float(mean - disc)
