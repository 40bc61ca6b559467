"""Per-span polynomial patches for many scattered positions and partials to order 2
(compiled, numba): a span search and a Horner scheme a point, what OCCT's
``BSplSLib_Cache`` does.

The table holds ``(p+1)(q+1)`` homogeneous 4-vectors per span pair, so it is built only for
small nets of degree up to 3 (:func:`suits`), where Horner's rounding stays at the level of
the basis-function sums.  :mod:`surfmod.eval.local` runs these kernels with :func:`arguments`.
See :doc:`/design_eval` (section "The compiled paths").

>>> import numpy as np
>>> from surfmod.eval import local
>>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> prepared = local.prepare(knots, 3, knots, 3, net)
>>> out = np.empty((1, 3))
>>> patch_positions_compiled(*arguments(prepared, build_table(prepared), np.array([0.5]), np.array([0.25]), out))
>>> out
array([[1.5 , 0.75, 0.  ]])
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, uint64

from .kernels import SCATTER_CHUNK, basis_ders_point, find_span_bucketed, quotient_order2

#: largest table built (bytes): 100 x 100 bicubic spans fit, the table stays cache-friendly
MAX_TABLE_BYTES = 8 << 20
#: highest degree in either direction (see the module docstring on rounding)
MAX_DEGREE = 3
#: largest ratio of a rational net's weights: where the weight varies by orders of
#: magnitude across a span, the power-basis sums cancel (Horner from the midpoint of a span
#: whose weights run from 1 to 8e3: partials 1e-12 relative off, the basis kernel 2e-15;
#: OCCT's cache loses 2e-11), so such nets take the basis-function kernel
MAX_WEIGHT_RATIO = 1e3
#: largest ratio of a direction's longest knot span to its shortest: the Taylor rows of a
#: span beside much longer ones carry its neighbours' poles scaled by half-width powers,
#: and their sums lose digits of the second partials (crowded bicubics, spans 1e-4..1e-6 of
#: the domain: 2.8e-12 relative where the basis kernel and OCCT keep 3e-15; nist_ctc_05's
#: rational faces, span ratios 21..37: 1.8e-12..3.1e-12 where OCCT keeps 4.5e-13..7.3e-13),
#: so such nets take the basis-function kernel (sm.conformance, cases stress and corpus)
MAX_SPAN_RATIO = 10.0
#: points located per pass of the patch kernel (see :func:`positions_chunk`)
LOCATE_BLOCK = 128
# unsigned offset steps (an unsigned plus a signed integer would be typed float64)
U1, U2, U3, U4, U8, U12 = (np.uint64(k) for k in (1, 2, 3, 4, 8, 12))


class PatchTable(NamedTuple):
    """Taylor coefficients of every span pair and the spans' midpoints and scales."""

    coeffs: np.ndarray  # (n - p, m - q, p + 1, q + 1, 4): C[su - p, sv - q, k, l, d]
    mid_u: np.ndarray  # (n,) span midpoints (0 outside the domain's spans)
    scale_u: np.ndarray  # (n,) 1 / half-width (0 for an empty span)
    mid_v: np.ndarray
    scale_v: np.ndarray


def suits(p: int, q: int, n: int, m: int, weights=None, knots=()) -> bool:
    """Whether a table for degrees ``(p, q)`` and an ``n x m`` net (with ``weights``, if
    rational, and its ``knots`` vectors, if given) is worth building and keeps the kernels'
    precision."""
    size = (n - p) * (m - q) * (p + 1) * (q + 1) * 4 * 8
    if max(p, q) > MAX_DEGREE or size > MAX_TABLE_BYTES:
        return False
    for vector in knots:
        spans = np.diff(vector)
        spans = spans[spans > 0]
        if spans.size and spans.max() > MAX_SPAN_RATIO * spans.min():
            return False
    return weights is None or bool(weights.max() <= MAX_WEIGHT_RATIO * weights.min())


@njit(cache=True, error_model="numpy")
def _taylor_rows(knots, p, n, inv, rows, mid, scale):
    """``rows[s, k, i] = N_{s-p+i}^(k)(mid_s) half_s^k / k!`` for every non-empty span."""
    ndu = np.empty((p + 1, p + 1))
    left, right, tmp = np.empty(p + 1), np.empty(p + 1), np.empty(p + 1)
    ders = np.empty((p + 1, p + 1))
    for s in range(p, n):
        a, b = knots[s], knots[s + 1]
        if not b > a:
            continue  # an empty span is never the span of a parameter
        half = 0.5 * (b - a)
        mid[s] = a + half
        scale[s] = 1.0 / half
        basis_ders_point(knots, p, s, mid[s], p, inv, ndu, left, right, tmp, ders)
        factor = 1.0
        for k in range(p + 1):
            for i in range(p + 1):
                rows[s, k, i] = ders[k, i] * factor
            factor *= half / (k + 1)


@njit(cache=True, error_model="numpy")
def _contract(rows_u, rows_v, p, q, ctrl, coeffs):
    """``coeffs[su-p, sv-q, k, l] = sum_ij rows_u[su, k, i] rows_v[sv, l, j] P[su-p+i, sv-q+j]``."""
    n, m = ctrl.shape[0], ctrl.shape[1]
    by_v = np.empty((q + 1, 4))
    for su in range(p, n):
        for sv in range(q, m):
            c = coeffs[su - p, sv - q]
            c[:] = 0.0
            for i in range(p + 1):
                for l in range(q + 1):
                    for d in range(4):
                        acc = 0.0
                        for j in range(q + 1):
                            acc += rows_v[sv, l, j] * ctrl[su - p + i, sv - q + j, d]
                        by_v[l, d] = acc
                for k in range(p + 1):
                    t = rows_u[su, k, i]
                    for l in range(q + 1):
                        for d in range(4):
                            c[k, l, d] += t * by_v[l, d]


def build_table(net) -> PatchTable:
    """The patch table of a :class:`surfmod.eval.local.LocalNet` (see :func:`suits`)."""
    n, m = net.ctrl.shape[:2]
    p, q = net.p, net.q
    rows_u, rows_v = np.zeros((n, p + 1, p + 1)), np.zeros((m, q + 1, q + 1))
    mid_u, scale_u, mid_v, scale_v = np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(m)
    _taylor_rows(net.knots_u, p, n, net.inv_u, rows_u, mid_u, scale_u)
    _taylor_rows(net.knots_v, q, m, net.inv_v, rows_v, mid_v, scale_v)
    coeffs = np.empty((n - p, m - q, p + 1, q + 1, 4))
    _contract(rows_u, rows_v, p, q, net.ctrl, coeffs)
    return PatchTable(coeffs, mid_u, scale_u, mid_v, scale_v)


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _cubic_in_y(c, o, y):
    """``sum_l c[o + 4 l] y^l`` (one coordinate of one row of a bicubic patch) by Horner;
    ``o`` unsigned (see :func:`positions_chunk`)."""
    return ((c[o + U12] * y + c[o + U8]) * y + c[o + U4]) * y + c[o]


# Horner steps may fuse into FMAs ("contract"): one rounding instead of two, never a
# reassociated sum, so the results stay within an ulp or so of the unfused ones.
@njit(cache=True, error_model="numpy")
def patch_positions_compiled(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                             bucket_u, bucket_v, u, v, out, origin=None):
    """Positions at scattered pairs into ``out (N, 3)``, chunk after chunk (the serial twin
    of :func:`surfmod.eval.parallel.patch_positions_parallel`); arguments: :func:`arguments`, and
    the ``origin`` added to the positions (a far net's centre), if any."""
    for c in range((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        positions_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                        bucket_u, bucket_v, u, v, out, c, origin)


@njit(cache=True, error_model="numpy")
def positions_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                    bucket_u, bucket_v, u, v, out, chunk, origin=None):
    """Points ``chunk * SCATTER_CHUNK`` onwards (one chunk) of :func:`positions`; the
    parallel variant (:mod:`surfmod.eval.parallel`) runs the chunks on several threads.

    In two passes per block of :data:`LOCATE_BLOCK` points: first every point's patch and
    local parameters (span searches), then the Horner schemes.  Apart, each loop keeps
    many independent points in flight; together, the span search's chain of dependent
    loads stalls the arithmetic (a fifth slower)."""
    a0, a1 = chunk * SCATTER_CHUNK, min(u.size, (chunk + 1) * SCATTER_CHUNK)
    flat = coeffs.reshape(-1)  # flat offsets: no array view per point
    per_span = uint64((p + 1) * (q + 1) * 4)
    per_row = uint64(m - q) * per_span
    base = np.empty(LOCATE_BLOCK, dtype=np.uint64)
    xs, ys = np.empty(LOCATE_BLOCK), np.empty(LOCATE_BLOCK)
    for c0 in range(a0, a1, LOCATE_BLOCK):
        c1 = min(a1, c0 + LOCATE_BLOCK)
        for i in range(c1 - c0):
            base[i], xs[i], ys[i] = _local_parameters(ku, p, kv, q, n, m, mid_u, scale_u, mid_v, scale_v, bucket_u,
                                                      bucket_v, u[c0 + i], v[c0 + i], per_row, per_span)
        if p == 3 and q == 3:
            _bicubic_points(flat, coeffs.shape[-1], base, xs, ys, rational, out, c0, c1)
        else:
            _patch_points(flat, p, q, base, xs, ys, rational, out, c0, c1)
        if origin is not None:  # while the block is in cache
            for i in range(c0, c1):
                for d in range(3):
                    out[i, d] += origin[d]


@njit(cache=True, inline="always", error_model="numpy")
def _local_parameters(ku, p, kv, q, n, m, mid_u, scale_u, mid_v, scale_v, bucket_u, bucket_v, ua, va, per_row,
                      per_span):
    """A point's offset of its patch in the flat table (unsigned: numba then skips the
    negative-index wraparound, a compare and a select, of every load) and its normalized
    parameters in ``[-1, 1]``."""
    su = find_span_bucketed(ku, p, n, ua, bucket_u[0], bucket_u[1], bucket_u[2])
    sv = find_span_bucketed(kv, q, m, va, bucket_v[0], bucket_v[1], bucket_v[2])
    x = (ua - mid_u[su]) * scale_u[su]
    y = (va - mid_v[sv]) * scale_v[sv]
    return uint64(su - p) * per_row + uint64(sv - q) * per_span, x, y


@njit(cache=True, inline="always", error_model="numpy")
def _store(out, a, h0, h1, h2, h3, rational):
    if rational:
        inv_w = 1.0 / h3
        h0 *= inv_w
        h1 *= inv_w
        h2 *= inv_w
    out[a, 0] = h0
    out[a, 1] = h1
    out[a, 2] = h2


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _bicubic_points(flat, dim, base, xs, ys, rational, out, c0, c1):
    """Bicubic patches for points ``c0:c1`` (located in ``base``, ``xs``, ``ys``): the four
    coordinates of a row side by side in one 4-wide loop.  Its trip count ``dim`` (4) is
    a run-time value on purpose: LLVM then keeps the loop and vectorizes it (4-wide FMAs)
    instead of unrolling it into scalar code (numba runs no SLP vectorizer)."""
    h = np.empty(4)
    for i in range(c1 - c0):
        x, y = xs[i], ys[i]
        o = base[i] + uint64(48)
        for d in range(dim):
            h[d] = _cubic_in_y(flat, o + uint64(d), y)
        for k in range(2, -1, -1):
            o = base[i] + uint64(16 * k)
            for d in range(dim):
                h[d] = h[d] * x + _cubic_in_y(flat, o + uint64(d), y)
        _store(out, c0 + i, h[0], h[1], h[2], h[3], rational)


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _patch_points(flat, p, q, base, xs, ys, rational, out, c0, c1):
    """Any degrees up to :data:`MAX_DEGREE`: nested Horner schemes, inner over y."""
    for i in range(c1 - c0):
        x, y = xs[i], ys[i]
        h0 = h1 = h2 = h3 = 0.0
        for k in range(p, -1, -1):
            o = base[i] + uint64(4 * (q + 1) * k)
            t = o + uint64(4 * q)
            s0, s1, s2, s3 = flat[t], flat[t + U1], flat[t + U2], flat[t + U3]
            for l in range(q - 1, -1, -1):
                t = o + uint64(4 * l)
                s0 = s0 * y + flat[t]
                s1 = s1 * y + flat[t + U1]
                s2 = s2 * y + flat[t + U2]
                s3 = s3 * y + flat[t + U3]
            h0 = h0 * x + s0
            h1 = h1 * x + s1
            h2 = h2 * x + s2
            h3 = h3 * x + s3
        _store(out, c0 + i, h0, h1, h2, h3, rational)


@njit(cache=True, error_model="numpy")
def patch_derivatives_compiled(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                               bucket_u, bucket_v, u, v, out, origin=None):
    """Partials to order 1 or 2 at scattered pairs into ``out (N, K, K, 3)``, chunk after
    chunk (the serial twin of :func:`surfmod.eval.parallel.patch_derivatives_parallel`)."""
    for c in range((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        derivatives_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                          bucket_u, bucket_v, u, v, out, c, origin)


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def derivatives_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational,
                      bucket_u, bucket_v, u, v, out, chunk, origin=None):
    """Partials to order 1 or 2 (``out (N, K, K, 3)``, ``K = 2, 3``) of the points of
    one chunk from their patches: per point, Horner schemes with their first two
    derivatives, in y over each x-power's row, then in x over the results; the chain
    rule's scales ``scale^k``; the quotient rule.  The four homogeneous coordinates go
    side by side in 4-wide loops whose trip count is a run-time value, so that LLVM
    vectorizes them (as in :func:`_bicubic_points`)."""
    a0, a1 = chunk * SCATTER_CHUNK, min(u.size, (chunk + 1) * SCATTER_CHUNK)
    kk = out.shape[1]
    dim = coeffs.shape[-1]
    flat = coeffs.reshape(-1)
    per_span = uint64((p + 1) * (q + 1) * 4)
    per_row = uint64(m - q) * per_span
    by_y = np.empty((p + 1, 3, 4))  # [x power, y-derivative order, coordinate]
    h = np.empty((3, 3, 4))  # [u-order, v-order, coordinate]
    for a in range(a0, a1):
        su = find_span_bucketed(ku, p, n, u[a], bucket_u[0], bucket_u[1], bucket_u[2])
        sv = find_span_bucketed(kv, q, m, v[a], bucket_v[0], bucket_v[1], bucket_v[2])
        x = (u[a] - mid_u[su]) * scale_u[su]
        y = (v[a] - mid_v[sv]) * scale_v[sv]
        base = uint64(su - p) * per_row + uint64(sv - q) * per_span
        for k in range(p + 1):
            row = base + uint64(4 * (q + 1) * k)
            for d in range(dim):
                f0 = flat[row + uint64(4 * q + d)]
                f1 = f2 = 0.0
                for j in range(q - 1, -1, -1):
                    f2 = f2 * y + f1
                    f1 = f1 * y + f0
                    f0 = f0 * y + flat[row + uint64(4 * j + d)]
                by_y[k, 0, d], by_y[k, 1, d], by_y[k, 2, d] = f0, f1, 2.0 * f2
        sx, sy = scale_u[su], scale_v[sv]
        for l in range(3):
            for d in range(dim):
                f0 = by_y[p, l, d]
                f1 = f2 = 0.0
                for i in range(p - 1, -1, -1):
                    f2 = f2 * x + f1
                    f1 = f1 * x + f0
                    f0 = f0 * x + by_y[i, l, d]
                h[0, l, d], h[1, l, d], h[2, l, d] = f0, f1 * sx, 2.0 * f2 * sx * sx
            sl = sy if l == 1 else (sy * sy if l == 2 else 1.0)
            for k in range(3):
                for d in range(dim):
                    h[k, l, d] *= sl
        _store_partials(h, rational, out, a, kk)
        if origin is not None:
            for d in range(3):
                out[a, 0, 0, d] += origin[d]


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_partials(h, rational, out, a, kk):
    """``out[a, :kk, :kk]`` from the homogeneous partials ``h[k, l, :]`` (the quotient rule,
    :func:`surfmod.eval.kernels.quotient_order2`, when rational: the entries of order 1
    need only lower ones, so they are the same as to order 2)."""
    if not rational:
        for k in range(kk):
            for l in range(kk):
                for d in range(3):
                    out[a, k, l, d] = h[k, l, d]
        return
    iw = 1.0 / h[0, 0, 3]
    v01, v02, v10, v11, v12 = h[0, 1, 3], h[0, 2, 3], h[1, 0, 3], h[1, 1, 3], h[1, 2, 3]
    v20, v21, v22 = h[2, 0, 3], h[2, 1, 3], h[2, 2, 3]
    for d in range(3):
        s00, s01, s02, s10, s11, s12, s20, s21, s22 = quotient_order2(
            h[0, 0, d], h[0, 1, d], h[0, 2, d], h[1, 0, d], h[1, 1, d], h[1, 2, d], h[2, 0, d], h[2, 1, d], h[2, 2, d],
            iw, v01, v02, v10, v11, v12, v20, v21, v22)
        out[a, 0, 0, d], out[a, 0, 1, d], out[a, 1, 0, d], out[a, 1, 1, d] = s00, s01, s10, s11
        if kk == 3:
            out[a, 0, 2, d], out[a, 1, 2, d] = s02, s12
            out[a, 2, 0, d], out[a, 2, 1, d], out[a, 2, 2, d] = s20, s21, s22


def arguments(net, table: PatchTable, u: np.ndarray, v: np.ndarray, out: np.ndarray) -> tuple:
    """The arguments of :func:`patch_positions_compiled` and :func:`patch_derivatives_compiled` (and of their
    parallel variants) for ``net``'s table at the scattered pairs ``(u[a], v[a])`` (flat
    float64 arrays, in the domain), writing ``out``."""
    n, m = net.ctrl.shape[:2]
    return (net.knots_u, net.p, net.knots_v, net.q, n, m, table.coeffs, table.mid_u, table.scale_u, table.mid_v,
            table.scale_v, net.rational, net.bucket_u, net.bucket_v, u, v, out)
