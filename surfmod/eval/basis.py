"""B-spline and Bernstein basis functions with derivatives, vectorized over parameters.

The loops run over the degree and the derivative order only (Piegl & Tiller, *The NURBS
Book*, algorithms A2.1 and A2.3, with every scalar replaced by an array over the
parameters).  A Bézier basis of degree n is the B-spline basis on the clamped knot vector
``[0]*(n+1) + [1]*(n+1)``, so both share this code.
"""

from __future__ import annotations

import numpy as np


def find_spans(knots: np.ndarray, degree: int, n_ctrl: int, t: np.ndarray) -> np.ndarray:
    """Index ``i`` with ``knots[i] <= t < knots[i+1]`` for each t, inside ``[degree, n_ctrl-1]``.

    The right end of the domain belongs to the last non-empty span, as in OCCT.
    """
    spans = np.searchsorted(knots, t, side="right") - 1
    return np.clip(spans, degree, n_ctrl - 1)


def knots_inside(knots, lo: float, hi: float, period: float | None = None) -> np.ndarray:
    """The distinct values of ``knots`` strictly inside ``(lo, hi)``, sorted; with a
    ``period`` (a periodic spline) repeated every period first, so a range past the knot
    vector's ends still meets every knot it crosses.  Where a spline is no smoother than
    ``C^(p-1)``: the breaks of a quadrature.

    >>> knots_inside([0, 0, 1, 2, 2], 0.5, 2.0).tolist()
    [1.0]
    >>> knots_inside([0, 1, 2], -1.5, 1.5, period=2.0).tolist()
    [-1.0, 0.0, 1.0]
    """
    k = np.unique(np.asarray(knots, dtype=float))
    if period is not None and len(k):
        shifts = np.arange(np.floor((lo - k[-1]) / period), np.ceil((hi - k[0]) / period) + 1)
        k = np.unique((k[None, :] + period * shifts[:, None]).ravel())
    return k[(k > lo) & (k < hi)]


def basis_derivatives(knots: np.ndarray, degree: int, spans: np.ndarray, t: np.ndarray, order: int) -> np.ndarray:
    """Non-zero basis functions and their derivatives.

    Returns ``ders`` of shape ``(len(t), order + 1, degree + 1)`` where ``ders[a, k, r]`` is the
    k-th derivative of ``N_{spans[a] - degree + r, degree}`` at ``t[a]``.  Derivatives above
    the degree are zero.  The tables are kept with the points on the last axis, so every
    step of the recurrence is one contiguous array operation; the result is a view in the
    documented axis order.
    """
    p = degree
    t = np.asarray(t, dtype=float).ravel()
    n_pts = t.size
    # ndu[j, r]: upper triangle = basis functions of rising degree, lower = knot differences
    ndu = np.zeros((p + 1, p + 1, n_pts))
    ndu[0, 0] = 1.0
    left = np.zeros((p + 1, n_pts))
    right = np.zeros((p + 1, n_pts))
    for j in range(1, p + 1):
        left[j] = t - knots[spans + 1 - j]
        right[j] = knots[spans + j] - t
        saved = np.zeros(n_pts)
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            temp = ndu[r, j - 1] / ndu[j, r]
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved

    ders = np.zeros((order + 1, p + 1, n_pts))
    ders[0] = ndu[:, p]
    top = min(order, p)
    for r in range(p + 1 if top > 0 else 0):
        a = np.zeros((2, p + 1, n_pts))
        a[0, 0] = 1.0
        s1, s2 = 0, 1
        for k in range(1, top + 1):
            d = np.zeros(n_pts)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, 0] = a[s1, 0] / ndu[pk + 1, rk]
                d += a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            if j2 >= j1:
                js = slice(j1, j2 + 1)
                a[s2, js] = (a[s1, js] - a[s1, j1 - 1 : j2]) / ndu[pk + 1, rk + j1 : rk + j2 + 1]
                d += np.einsum("jn,jn->n", a[s2, js], ndu[rk + j1 : rk + j2 + 1, pk])
            if r <= pk:
                a[s2, k] = -a[s1, k - 1] / ndu[pk + 1, r]
                d += a[s2, k] * ndu[r, pk]
            ders[k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, top + 1):
        ders[k] *= factor
        factor *= p - k
    return ders.transpose(2, 0, 1)


def clamped_bezier_knots(degree: int) -> np.ndarray:
    """The knot vector on which the B-spline basis of ``degree`` is the Bernstein basis."""
    return np.concatenate([np.zeros(degree + 1), np.ones(degree + 1)])


def basis_matrix(knots: np.ndarray, degree: int, n_ctrl: int, t: np.ndarray, order: int = 0) -> np.ndarray:
    """Dense basis matrices ``B[k, a, i] = d^k N_i(t_a)``, shape ``(order+1, len(t), n_ctrl)``.

    Used for grid evaluation, where two BLAS products beat any gather.
    """
    t = np.asarray(t, dtype=float).ravel()
    spans = find_spans(knots, degree, n_ctrl, t)
    ders = basis_derivatives(knots, degree, spans, t, order)
    mat = np.zeros((order + 1, t.size, n_ctrl))
    rows = np.arange(t.size)[:, None]
    cols = spans[:, None] - degree + np.arange(degree + 1)[None, :]
    for k in range(order + 1):
        mat[k, rows, cols] = ders[:, k, :]
    return mat


def reciprocal_table(knots: np.ndarray, degree: int, n_ctrl: int) -> np.ndarray:
    """``inv[span, j, r] = 1 / (knots[span+r+1] - knots[span+r+1-j])`` for the spans of the
    domain and ``r < j <= degree`` (other entries 0, as is an empty difference: the 0/0 = 0
    convention): the divisors of the Cox-de Boor triangle, which the compiled kernels
    multiply by instead of dividing.  Every such difference spans the non-empty knot
    interval ``[knots[span], knots[span+1])``.

    >>> reciprocal_table(np.array([0, 0, 1, 2, 2.0]), 1, 3)[1:, 1, 0].tolist()
    [1.0, 1.0]
    """
    p = degree
    inv = np.zeros((n_ctrl, p + 1, p + 1))
    span, j, r = np.meshgrid(np.arange(p, n_ctrl), np.arange(1, p + 1), np.arange(p + 1), indexing="ij")
    keep = r < j
    span, j, r = span[keep], j[keep], r[keep]
    diff = knots[span + r + 1] - knots[span + r + 1 - j]
    with np.errstate(divide="ignore"):
        inv[span, j, r] = np.where(diff > 0, 1.0 / diff, 0.0)
    return inv


def span_buckets(knots: np.ndarray, degree: int, n_ctrl: int, per_span: int = 4):
    """``(t0, scale, table)`` for the compiled O(1) span search
    (:func:`surfmod.eval.kernels.find_span_bucketed`): ``per_span`` buckets per knot span
    over ``[knots[degree], knots[n_ctrl]]``, each holding the span of its start.

    >>> span_buckets(np.array([0, 0, 1, 2, 2.0]), 1, 3, per_span=1)[2].tolist()
    [1, 2]
    """
    t0, t1 = float(knots[degree]), float(knots[n_ctrl])
    count = max(1, per_span * (n_ctrl - degree))
    starts = t0 + (t1 - t0) * np.arange(count) / count
    table = find_spans(knots, degree, n_ctrl, starts).astype(np.int64)
    return t0, (count / (t1 - t0) if t1 > t0 else 0.0), table
