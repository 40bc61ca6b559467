"""Making B-spline curves compatible: degree elevation, reparametrization to a common
interval and knot merging (the steps of OCCT's ``GeomFill_Profiler``).

Degree elevation is in closed form (Piegl & Tiller, *The NURBS Book*, algorithm A5.9):
the spline is cut into Bezier segments by knot insertion, each segment is elevated by the
binomial formula, and the knots are removed again down to their old multiplicity plus
``t``.  No linear system is solved, so the result stays exact to round-off at any degree
and equals OCCT's ``Geom_BSplineCurve::IncreaseDegree``.  Rational curves are elevated in
homogeneous coordinates.
"""

from __future__ import annotations

from math import comb

import numpy as np

from . import knots as kn
from .bspline import BSplineCurve, cartesian, homogeneous

#: OCCT's Precision::PConfusion(), the tolerance under which two knots are the same.
KNOT_TOL = 1e-9


def clamped(curve: BSplineCurve) -> BSplineCurve:
    """The curve over its domain with clamped end knots (unchanged if already clamped)."""
    p, k = curve.degree, curve.knots
    n = curve.control_points.shape[0]
    if np.all(k[: p + 1] == k[p]) and np.all(k[n:] == k[n]):
        return curve
    return curve.segment(*curve.domain)


def elevate_degree(knots: np.ndarray, degree: int, ctrl: np.ndarray, times: int, axis: int = 0):
    """Raise the degree of a clamped spline by ``times``: ``(new_knots, new_ctrl)``.

    ``ctrl`` holds the control index along ``axis`` (homogeneous for rational splines);
    the other axes ride along (coordinates, the other direction of a surface's net).

    >>> import numpy as np
    >>> k, c = elevate_degree(np.array([0., 0, 1, 1]), 1, np.array([[0., 0], [2, 0]]), 1)
    >>> k.tolist(), c.tolist()
    ([0.0, 0.0, 0.0, 1.0, 1.0, 1.0], [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    """
    if times <= 0:
        return knots, ctrl
    U = np.asarray(knots, dtype=float)
    moved = np.moveaxis(np.asarray(ctrl, dtype=float), axis, 0)
    pw = moved.reshape(moved.shape[0], -1)  # the trailing axes ride along as columns
    p, t, m = degree, times, U.size - 1
    ph = p + t
    values, counts = np.unique(U, return_counts=True)
    new_knots = np.repeat(values, counts + t)
    alf_bez = _elevation_matrix(p, t)
    qw = np.zeros((new_knots.size - ph - 1,) + pw.shape[1:])
    uh = np.empty(new_knots.size)
    uh[: ph + 1], qw[0] = U[0], pw[0]
    bpts, next_bpts = pw[: p + 1].copy(), np.empty_like(pw[: p + 1])
    kind, cind, r, a, b, ua = ph + 1, 1, -1, p, p + 1, U[0]
    while b < m:  # one pass per distinct interior knot and the end (at most len(knots))
        i = b
        while b < m and U[b] == U[b + 1]:
            b += 1
        mul, ub = b - i + 1, U[b]
        oldr, r = r, p - mul
        lbz = (oldr + 2) // 2 if oldr > 0 else 1
        rbz = ph - (r + 1) // 2 if r > 0 else ph
        if r > 0:  # insert ub r times: the Bezier segment [ua, ub] is in bpts
            alfs = (ub - ua) / (U[a + mul + 1: a + p + 1] - ua)
            for j in range(1, r + 1):
                al = alfs[: p - (s := mul + j) + 1, None]
                bpts[s:] = al * bpts[s:] + (1 - al) * bpts[s - 1: p]
                next_bpts[r - j] = bpts[p]
        ebpts = alf_bez @ bpts  # the segment elevated (binomial form)
        if oldr > 1:  # remove the knot ua oldr - 1 times
            first, last, den = kind - 2, kind, ub - ua
            bet = (ub - uh[kind - 1]) / den
            for tr in range(1, oldr):
                i, j, kj = first, last, last - kind + 1
                while j - i > tr:
                    if i < cind:
                        alf = (ub - uh[i]) / (ua - uh[i])
                        qw[i] = alf * qw[i] + (1 - alf) * qw[i - 1]
                    if j >= lbz:
                        if j - tr <= kind - ph + oldr:
                            gam = (ub - uh[j - tr]) / den
                            ebpts[kj] = gam * ebpts[kj] + (1 - gam) * ebpts[kj + 1]
                        else:
                            ebpts[kj] = bet * ebpts[kj] + (1 - bet) * ebpts[kj + 1]
                    i, j, kj = i + 1, j - 1, kj - 1
                first, last = first - 1, last + 1
        if a != p:
            uh[kind: kind + ph - oldr] = ua
            kind += ph - oldr
        qw[cind: cind + rbz - lbz + 1] = ebpts[lbz: rbz + 1]
        cind += rbz - lbz + 1
        if b < m:
            bpts[:r] = next_bpts[:r]
            bpts[r:] = pw[b - p + r: b + 1]
            a, b, ua = b, b + 1, ub
    return new_knots, np.moveaxis(qw.reshape((-1,) + moved.shape[1:]), 0, axis)


def _elevation_matrix(p: int, t: int) -> np.ndarray:
    """Bernstein coefficients of degree ``p + t`` from those of degree ``p``: entry ``(i, j)``
    is ``C(p, j) C(t, i - j) / C(p + t, i)`` (exact binomials, each row sums to one)."""
    i, j = np.meshgrid(np.arange(p + t + 1), np.arange(p + 1), indexing="ij")
    num = np.vectorize(lambda a, b: comb(p, b) * comb(t, a - b) if 0 <= a - b <= t else 0, otypes=[float])(i, j)
    return num / np.array([comb(p + t, k) for k in range(p + t + 1)], dtype=float)[:, None]


def elevated(curve: BSplineCurve, degree: int) -> BSplineCurve:
    """The same curve at degree ``degree`` (>= its own)."""
    c = clamped(curve)
    k, h = elevate_degree(c.knots, c.degree, homogeneous(c.control_points, c.weights), degree - c.degree)
    pts, w = cartesian(h, c.weights is not None)
    return BSplineCurve._trusted(pts, degree, k, w)


def rescaled_knots(knots: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """The knot vector mapped affinely onto ``[t0, t1]``, its ends exactly there."""
    new = t0 + (knots - knots[0]) * ((t1 - t0) / (knots[-1] - knots[0]))
    new[0], new[-1] = t0, t1
    return np.clip(new, t0, t1)


def reparametrized(curve: BSplineCurve, t0: float, t1: float) -> BSplineCurve:
    """Affine change of parameter mapping the (clamped) knot range onto ``[t0, t1]``."""
    return BSplineCurve._trusted(curve.control_points, curve.degree, rescaled_knots(curve.knots, t0, t1),
                                 curve.weights)


def inserted(knots, degree: int, ctrl: np.ndarray, values, mults, tol: float = KNOT_TOL, axis: int = 0):
    """Insert knots so that each ``values[i]`` has multiplicity at least ``mults[i]``
    (at most the degree, or degree + 1 at the ends); a knot within ``tol`` of an
    existing one raises that knot's multiplicity instead (as OCCT's ``InsertKnots`` with a
    parametric tolerance).  ``ctrl`` as in :func:`elevate_degree`; returns ``(knots, ctrl)``."""
    a = np.moveaxis(ctrl, axis, 0)
    for value, mult in zip(values, mults):
        existing = np.unique(knots)
        near = existing[np.abs(existing - value) <= tol]
        at = float(near[0]) if near.size else float(value)
        cap = degree + 1 if at in (knots[0], knots[-1]) else degree
        need = min(int(mult), cap) - kn.multiplicity(knots, at)
        if need > 0:
            knots, a = kn.insert_knot(knots, degree, a, at, need)
    return knots, np.moveaxis(a, 0, axis)


def merged_knots(knot_vectors, tol: float = KNOT_TOL):
    """Distinct knot values and maximal multiplicities over all knot vectors, sorted (the
    first vector's values win when two are within ``tol``)."""
    values: list[float] = []
    mults: list[int] = []
    for knots in knot_vectors:
        vals, counts = np.unique(knots, return_counts=True)
        for v, m in zip(vals, counts):
            hit = [i for i, x in enumerate(values) if abs(x - v) <= tol]
            if hit:
                mults[hit[0]] = max(mults[hit[0]], int(m))
            else:
                values.append(float(v))
                mults.append(int(m))
    order = np.argsort(values)
    return np.asarray(values)[order], np.asarray(mults)[order]


def compatible(splines, tol: float = KNOT_TOL, axis: int = 0):
    """One degree and one knot vector for clamped splines ``[(knots, degree, ctrl)]`` over
    one parameter interval: each is elevated to the highest degree and given the union of
    all knots at their highest multiplicities (exact: the splines do not change).  Knots
    within ``tol`` count as one, and the first spline's value is the one kept; ``tol=0``
    merges equal knots only.  ``ctrl`` as in :func:`elevate_degree`.  Returns
    ``(degree, knots, [ctrl, ...])``.

    >>> import numpy as np
    >>> line = (np.array([0., 0, 1, 1]), 1, np.array([[0.], [2.]]))
    >>> bump = (np.array([0., 0, 0, 0.5, 1, 1, 1]), 2, np.array([[0.], [1.], [1.], [0.]]))
    >>> p, k, (a, b) = compatible([line, bump])
    >>> p, k.tolist(), a.ravel().tolist()
    (2, [0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0], [0.0, 0.5, 1.5, 2.0])
    """
    degree = max(p for _, p, _ in splines)
    up = [elevate_degree(k, p, c, degree - p, axis) for k, p, c in splines]
    values, mults = merged_knots([k for k, _ in up], tol)
    knots, first = inserted(up[0][0], degree, up[0][1], values, mults, tol, axis)
    # the others take the first's knots, so a knot snapped in one is snapped in all
    values, mults = np.unique(knots, return_counts=True)
    return degree, knots, [first] + [inserted(k, degree, c, values, mults, tol, axis)[1] for k, c in up[1:]]


def make_compatible(curves, tol: float = KNOT_TOL):
    """Same degree, same parameter interval, same knot vector (``GeomFill_Profiler``):
    every curve is reparametrized onto the interval of the curve with the longest one
    (the first such curve wins), elevated to the highest degree and given the union of
    all knots (maximal multiplicities, :func:`compatible`).  Returns the list of
    compatible curves.

    >>> import surfmod as sm
    >>> a = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0)], 2)
    >>> b = sm.BSplineCurve([(0, 0, 1), (2, 0, 1)], 1, [0, 0, 2, 2])
    >>> [c.degree for c in make_compatible([a, b])], make_compatible([a, b])[0].domain
    ([2, 2], (0.0, 2.0))
    """
    curves = [clamped(c.to_bspline()) for c in curves]
    spans = [c.domain[1] - c.domain[0] for c in curves]
    widest = curves[int(np.argmax(spans))].domain
    degree, knots, nets = compatible(
        [(rescaled_knots(c.knots, *widest), c.degree, homogeneous(c.control_points, c.weights)) for c in curves], tol)
    out = [cartesian(h, c.weights is not None) for h, c in zip(nets, curves)]
    return [BSplineCurve._trusted(pts, degree, knots, w) for pts, w in out]
