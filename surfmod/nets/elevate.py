"""Making B-spline curves compatible: degree elevation, reparametrization to a common
interval and knot merging (the steps of OCCT's ``GeomFill_Profiler``).

Degree elevation is exact: the elevated spline lives in the space of degree ``p + t``
with every knot's multiplicity raised by ``t``, so the new control points are found by
collocation at that space's Greville abscissae (a square, well-conditioned,
Schoenberg-Whitney system).  The result equals OCCT's ``Geom_BSplineCurve::IncreaseDegree``
up to round-off.  Rational curves are elevated in homogeneous coordinates.
"""

from __future__ import annotations

import numpy as np

from ..eval.basis import basis_matrix
from ..eval.tensor import curve_derivatives
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


def elevate_degree(knots: np.ndarray, degree: int, ctrl: np.ndarray, times: int):
    """Raise the degree of a clamped spline by ``times``: ``(new_knots, new_ctrl)``.

    ``ctrl`` is ``(n, dim)`` (homogeneous for rational splines).

    >>> import numpy as np
    >>> k, c = elevate_degree(np.array([0., 0, 1, 1]), 1, np.array([[0., 0], [2, 0]]), 1)
    >>> k.tolist(), c.tolist()
    ([0.0, 0.0, 0.0, 1.0, 1.0, 1.0], [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    """
    if times <= 0:
        return knots, ctrl
    values, counts = np.unique(knots, return_counts=True)
    new_knots = np.repeat(values, counts + times)
    q = degree + times
    n_new = new_knots.size - q - 1
    windows = np.lib.stride_tricks.sliding_window_view(new_knots[1:-1], q)[:n_new]
    greville = windows.mean(axis=1)
    greville[0], greville[-1] = new_knots[q], new_knots[n_new]
    mat = basis_matrix(new_knots, q, n_new, greville)[0]
    rhs = curve_derivatives(knots, degree, ctrl, greville, 0)[:, 0]
    return new_knots, np.linalg.solve(mat, rhs)


def elevated(curve: BSplineCurve, degree: int) -> BSplineCurve:
    """The same curve at degree ``degree`` (>= its own)."""
    c = clamped(curve)
    k, h = elevate_degree(c.knots, c.degree, homogeneous(c.control_points, c.weights), degree - c.degree)
    pts, w = cartesian(h, c.weights is not None)
    return BSplineCurve._trusted(pts, degree, k, w)


def reparametrized(curve: BSplineCurve, t0: float, t1: float) -> BSplineCurve:
    """Affine change of parameter mapping the (clamped) knot range onto ``[t0, t1]``."""
    k = curve.knots
    new = t0 + (k - k[0]) * ((t1 - t0) / (k[-1] - k[0]))
    new[0], new[-1] = t0, t1
    new[new < t0] = t0
    new[new > t1] = t1
    return BSplineCurve._trusted(curve.control_points, curve.degree, new, curve.weights)


def with_knots(curve: BSplineCurve, values, mults, tol: float = KNOT_TOL) -> BSplineCurve:
    """Insert knots so that each ``values[i]`` has multiplicity at least ``mults[i]``; a
    knot within ``tol`` of an existing one raises that knot's multiplicity instead (as
    OCCT's ``InsertKnots`` with a parametric tolerance)."""
    k, h = curve.knots, homogeneous(curve.control_points, curve.weights)
    for value, mult in zip(values, mults):
        existing = np.unique(k)
        near = existing[np.abs(existing - value) <= tol]
        at = float(near[0]) if near.size else float(value)
        have = kn.multiplicity(k, at)
        cap = curve.degree + 1 if (at == k[0] or at == k[-1]) else curve.degree
        need = min(int(mult), cap) - have
        if need > 0:
            k, h = kn.insert_knot(k, curve.degree, h, at, need)
    pts, w = cartesian(h, curve.weights is not None)
    return BSplineCurve._trusted(pts, curve.degree, k, w)


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


def make_compatible(curves, tol: float = KNOT_TOL):
    """Same degree, same parameter interval, same knot vector (``GeomFill_Profiler``):
    every curve is elevated to the highest degree, reparametrized onto the interval of
    the curve with the longest one (the first such curve wins) and given the union of
    all knots (maximal multiplicities).  Returns the list of compatible curves.

    >>> import surfmod as sm
    >>> a = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0)], 2)
    >>> b = sm.BSplineCurve([(0, 0, 1), (2, 0, 1)], 1, [0, 0, 2, 2])
    >>> [c.degree for c in make_compatible([a, b])], make_compatible([a, b])[0].domain
    ([2, 2], (0.0, 2.0))
    """
    curves = [clamped(c.to_bspline()) for c in curves]
    degree = max(c.degree for c in curves)
    spans = [c.domain[1] - c.domain[0] for c in curves]
    widest = curves[int(np.argmax(spans))].domain
    curves = [reparametrized(elevated(c, degree), *widest) for c in curves]
    values, mults = merged_knots([c.knots for c in curves], tol)
    first = with_knots(curves[0], values, mults, tol)
    vals1, mults1 = np.unique(first.knots, return_counts=True)
    return [first] + [with_knots(c, vals1, mults1, tol) for c in curves[1:]]
