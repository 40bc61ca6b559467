"""Compiled (numba) kernels for tensor-product evaluation with local support: what the
``_compiled`` twins share (span search, basis functions, quotient rule).

Every sizeable array they write is allocated by the NumPy caller, so ``tracemalloc`` sees
the memory and the caller decides the blocking.  Conventions: ``ctrl`` is the homogeneous
net ``(n, m, dim)`` (``dim`` = 3 polynomial, 4 rational ``(w x, w y, w z, w)``),
C-contiguous float64; spans follow :func:`surfmod.eval.basis.find_spans` (the right end of
the domain belongs to the last span).  See :doc:`/design_eval`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# The per-point helpers below are plain compiled functions, not ``inline="always"``:
# numba's own inlining copies a helper into every caller and types it again there, which
# lengthens every first compile (design_eval.md, "Start-up, measured"), while LLVM still
# inlines them where it pays (the run times are the same, benchmarks/bench_eval.py).  quotient_order2 stays inlined: it must take its caller's
# floating-point flags.

# unsigned index steps: unsigned offsets spare numba's negative-index wraparound (a
# compare and a select per access), which otherwise keeps loops from vectorizing
U1, U2, U3 = np.uint64(1), np.uint64(2), np.uint64(3)


@njit(cache=True, error_model="numpy")
def find_span_bucketed(knots, degree, n_ctrl, t, t0, scale, table):
    """The largest ``i`` with ``knots[i] <= t``, clipped to the domain
    (:func:`surfmod.eval.basis.find_spans` of one parameter), in O(1): a uniform bucket
    grid over the domain gives a span at or just before the answer
    (:func:`~surfmod.eval.basis.span_buckets`), then a short, well-predicted walk.  The
    walk back guards against the rounding of the bucket index."""
    b = int((t - t0) * scale)
    if b < 0:
        b = 0
    elif b >= table.size:
        b = table.size - 1
    span = table[b]
    while span < n_ctrl - 1 and knots[span + 1] <= t:
        span += 1
    while span > degree and knots[span] > t:
        span -= 1
    return span


@njit(cache=True, error_model="numpy")
def basis_ders_point(knots, p, span, t, order, inv, ndu, left, right, tmp, ders):
    """The p+1 non-zero basis functions at ``t`` and their derivatives: ``ders[k, r]`` is
    the k-th derivative of ``N_{span-p+r}`` for ``k <= order`` (zero above the degree).

    The Cox-de Boor triangle ``ndu[r, j] = N_{span-j+r, j}`` keeps every lower degree;
    the k-th derivative starts from degree p-k and is raised k times by the textbook
    rule ``N'_{i,d} = d (N_{i,d-1} / (u_{i+d} - u_i) - N_{i+1,d-1} / (u_{i+d+1} - u_{i+1}))``
    (The NURBS Book eq. 2.9; A2.3 evaluates the same sums).  Every divisor is a knot
    difference whose reciprocal is in ``inv`` (:func:`reciprocal_table`; 0 for an empty
    difference, the 0/0 = 0 convention), so nothing divides.
    """
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = t - knots[span + 1 - j]
        right[j] = knots[span + j] - t
        saved = 0.0
        for r in range(j):
            temp = ndu[r, j - 1] * inv[span, j, r]
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    for r in range(p + 1):
        ders[0, r] = ndu[r, p]
    for k in range(1, order + 1):
        if k > p:
            for r in range(p + 1):
                ders[k, r] = 0.0
            continue
        for r in range(p - k + 1):
            tmp[r] = ndu[r, p - k]
        for d in range(p - k + 1, p + 1):
            # in place from the top: new[r] needs old[r - 1] and old[r]
            tmp[d] = d * (tmp[d - 1] * inv[span, d, d - 1])
            for r in range(d - 1, 0, -1):
                tmp[r] = d * (tmp[r - 1] * inv[span, d, r - 1] - tmp[r] * inv[span, d, r])
            tmp[0] = -d * (tmp[0] * inv[span, d, 0])
        for r in range(p + 1):
            ders[k, r] = tmp[r]


@njit(cache=True, error_model="numpy")
def quotient_point(h, binom, out):
    """Rational quotient rule (A4.4) at one point for the partials with ``k + l < K``
    (the triangle a Newton or curvature step needs): homogeneous ``h (K, K, 4)`` ->
    Cartesian ``out (K, K, 3)``; each entry needs only lower ones of the triangle."""
    kk = h.shape[0]
    inv_w = 1.0 / h[0, 0, 3]
    for k in range(kk):
        for l in range(kk - k):
            for d in range(3):
                v = h[k, l, d]
                for j in range(1, l + 1):
                    v -= binom[l, j] * h[0, j, 3] * out[k, l - j, d]
                for i in range(1, k + 1):
                    v -= binom[k, i] * h[i, 0, 3] * out[k - i, l, d]
                    v2 = 0.0
                    for j in range(1, l + 1):
                        v2 += binom[l, j] * h[i, j, 3] * out[k - i, l - j, d]
                    v -= binom[k, i] * v2
                out[k, l, d] = v * inv_w


def binomials(order: int) -> np.ndarray:
    """``C(k, i)`` table ``(order+1, order+1)`` for the quotient rule."""
    kk = order + 1
    out = np.zeros((kk, kk))
    for k in range(kk):
        out[k, 0] = 1.0
        for i in range(1, k + 1):
            out[k, i] = out[k - 1, i - 1] + (out[k - 1, i] if i < k else 0.0)
    return out


#: scattered points per chunk: the unit of work of the parallel variants
#: (:mod:`surfmod.eval.parallel`); a multiple of :data:`POINT_BLOCK`
SCATTER_CHUNK = 4096

@njit(cache=True, error_model="numpy")
def position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, u, v, lu, ru, nu_, lv, rv, nv_):
    """``(x, y, z)`` at one pair: bucketed span search, the A2.2 triangle in each
    direction and the ``(p+1) x (q+1)`` sum kept in registers (``lu``... ``nv_``: the
    caller's scratch of ``p + 1`` and ``q + 1`` values)."""
    n, m = ctrl.shape[0], ctrl.shape[1]
    su = find_span_bucketed(ku, p, n, u, bucket_u[0], bucket_u[1], bucket_u[2])
    sv = find_span_bucketed(kv, q, m, v, bucket_v[0], bucket_v[1], bucket_v[2])
    _basis_funs(ku, p, su, u, inv_u, lu, ru, nu_)
    _basis_funs(kv, q, sv, v, inv_v, lv, rv, nv_)
    x = y = z = w = 0.0
    for i in range(p + 1):
        rx = ry = rz = rw = 0.0
        ci = su - p + i
        for j in range(q + 1):
            c = nv_[j]
            cj = sv - q + j
            rx += c * ctrl[ci, cj, 0]
            ry += c * ctrl[ci, cj, 1]
            rz += c * ctrl[ci, cj, 2]
            rw += c * ctrl[ci, cj, 3]
        c = nu_[i]
        x += c * rx
        y += c * ry
        z += c * rz
        w += c * rw
    if rational:
        return x / w, y / w, z / w
    return x, y, z


@njit(cache=True, error_model="numpy")
def _basis_funs(knots, p, span, t, inv, left, right, out):
    """Piegl & Tiller A2.2: the p+1 non-zero basis functions at ``t``.  The denominators
    ``right[r+1] + left[j-r]`` are knot differences independent of ``t``; their
    reciprocals come from the table ``inv[span, j, r]`` (see :func:`reciprocal_table`),
    so the triangle has no division."""
    out[0] = 1.0
    for j in range(1, p + 1):
        left[j] = t - knots[span + 1 - j]
        right[j] = knots[span + j] - t
        saved = 0.0
        for r in range(j):
            temp = out[r] * inv[span, j, r]
            out[r] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        out[j] = saved


@njit(cache=True, error_model="numpy")
def quotient_planes(acc, binom):
    """The quotient rule in place on planes ``acc (K, K, 4, n)``: coordinates 0..2 of
    every entry become Cartesian, entry by entry in rising order (each needs only lower
    entries, already converted, and the untouched weight planes).  Every step is a pass
    over the contiguous last axis through 1-D views, so it vectorizes."""
    kk, nv = acc.shape[0], acc.shape[3]
    if kk == 3:
        _quotient_planes_order2(acc)
        return
    inv_w = np.empty(nv)
    w00 = acc[0, 0, 3]
    for b in range(nv):
        inv_w[b] = 1.0 / w00[b]
    for k in range(kk):
        for l in range(kk):
            for d in range(3):
                dst = acc[k, l, d]
                for i in range(k + 1):
                    for j in range(l + 1):
                        if i == 0 and j == 0:
                            continue
                        c = binom[k, i] * binom[l, j]
                        wij = acc[i, j, 3]
                        src = acc[k - i, l - j, d]
                        for b in range(nv):
                            dst[b] -= c * wij[b] * src[b]
                for b in range(nv):
                    dst[b] *= inv_w[b]


@njit(cache=True, error_model="numpy")
def _quotient_planes_order2(acc):
    """:func:`quotient_planes` for partials to order 2, written out: one pass over the
    points per coordinate with all nine entries in registers (the general version makes
    a pass per term).  Same terms in the same order, so the same rounding."""
    nv = acc.shape[3]
    w00, w01, w02 = acc[0, 0, 3], acc[0, 1, 3], acc[0, 2, 3]
    w10, w11, w12 = acc[1, 0, 3], acc[1, 1, 3], acc[1, 2, 3]
    w20, w21, w22 = acc[2, 0, 3], acc[2, 1, 3], acc[2, 2, 3]
    for d in range(3):
        a00, a01, a02 = acc[0, 0, d], acc[0, 1, d], acc[0, 2, d]
        a10, a11, a12 = acc[1, 0, d], acc[1, 1, d], acc[1, 2, d]
        a20, a21, a22 = acc[2, 0, d], acc[2, 1, d], acc[2, 2, d]
        for b in range(nv):
            s = quotient_order2(a00[b], a01[b], a02[b], a10[b], a11[b], a12[b], a20[b], a21[b], a22[b],
                                1.0 / w00[b], w01[b], w02[b], w10[b], w11[b], w12[b], w20[b], w21[b], w22[b])
            a00[b], a01[b], a02[b], a10[b], a11[b], a12[b], a20[b], a21[b], a22[b] = s


@njit(cache=True, inline="always", error_model="numpy")
def quotient_order2(a00, a01, a02, a10, a11, a12, a20, a21, a22, iw, v01, v02, v10, v11, v12, v20, v21, v22):
    """The quotient rule to order 2 for one coordinate of one point: the Cartesian
    partials ``s_kl`` of ``x / w`` from the homogeneous ``a_kl`` (of ``x w``), the
    weight's partials ``v_kl`` and ``iw = 1 / w``, each entry in rising order from the
    lower ones, ``s_kl = (a_kl - sum C(k,i) C(l,j) v_ij s_(k-i)(l-j)) iw``, the terms in
    the order of :func:`quotient_planes`.  Shared by every kernel that applies it (grid
    planes, the grid's order-2 stage, the per-span patches), whose layouts differ; it is
    inlined, so each is compiled with its caller's flags (fused multiply-adds or not).

    >>> s = quotient_order2(2.0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0)
    >>> s[0], s[8]
    (1.0, 0.0)
    """
    s00 = a00 * iw
    s01 = (a01 - v01 * s00) * iw
    s02 = (a02 - 2.0 * v01 * s01 - v02 * s00) * iw
    s10 = (a10 - v10 * s00) * iw
    s11 = (a11 - v01 * s10 - v10 * s01 - v11 * s00) * iw
    s12 = (a12 - 2.0 * v01 * s11 - v02 * s10 - v10 * s02 - 2.0 * v11 * s01 - v12 * s00) * iw
    s20 = (a20 - 2.0 * v10 * s10 - v20 * s00) * iw
    s21 = (a21 - v01 * s20 - 2.0 * v10 * s11 - 2.0 * v11 * s10 - v20 * s01 - v21 * s00) * iw
    s22 = (a22 - 2.0 * v01 * s21 - v02 * s20 - 2.0 * v10 * s12 - 4.0 * v11 * s11 - 2.0 * v12 * s10 - v20 * s02
           - 2.0 * v21 * s01 - v22 * s00) * iw
    return s00, s01, s02, s10, s11, s12, s20, s21, s22
