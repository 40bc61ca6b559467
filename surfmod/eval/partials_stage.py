"""Second stage of the grid for partials to order 2 (the 27 doubles a point of
``(n_u, N_v, 3, 3, 3)``), in chunks of :data:`CHUNK` v-points that stay in L1.

For each u-point and chunk: its p+1 rows of the row table are combined into the 36
planes ``acc[k, l, d, :]`` (each row window loaded once for all three ``k``), the
quotient rule runs over the chunk with each point's weights and their multiples loaded
once for the three coordinates, and each pair of points (54 doubles) goes to the output
as 27 aligned 16-byte stores, non-temporal when the caller asks for streaming
(:mod:`surfmod.eval.streaming`).  Done plane by plane over a whole v-row (the general
path of :func:`surfmod.eval.grid_kernels.grid_derivatives`), the same work moves every
plane through L2 three times; here only the row table is read from L2, and when
streaming not even that: the chunks then go column by column, so each chunk's row
windows stay in L1 for every u-point.

Every value is the same sum, in the same order, as in the general path, compiled with
fused multiply-adds (``fastmath={"contract"}``, nothing else): one rounding per term
instead of two, so the results equal the general path's to rounding (a few ulps of each
partial's size, ``tests/test_eval_partials_stage.py``) and are deterministic (the same
on one thread or several, for any blocking).
"""

from __future__ import annotations

import numpy as np
from numba import literally, njit, uint64

from .streaming import aligned_16, fence, stream_pair

#: v-points per chunk: 36 planes of 16 doubles (4.6 KiB) beside the row windows in L1;
#: short enough that the compute of one chunk overlaps the draining of the last one's
#: streamed stores
CHUNK = 16


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def order2_block(bu, first, p, w, rational, b0, out, stream):
    """Partials to order 2 of a block of u-points: ``out[a, b0:b0+n_v]`` from the row
    table ``w (rows, 3, dim, n_v)``, ``first[a]`` the place of u-point ``a``'s first row
    in it, ``bu (n_u, 3, p+1)`` the u-basis with its derivatives."""
    # one compiled chunk loop per (stream, combine): each holds only its own loop order
    # and combine (measured: with both in one loop, LLVM compiled it to half the speed)
    if stream:
        if p <= 3:
            _chunks(bu, first, p, w, rational, b0, out, True, False)
        else:
            _chunks(bu, first, p, w, rational, b0, out, True, True)
        fence()
    elif p <= 3:
        _chunks(bu, first, p, w, rational, b0, out, False, False)
    else:
        _chunks(bu, first, p, w, rational, b0, out, False, True)


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _chunks(bu, first, p, w, rational, b0, out, stream, high_degree):
    """The chunk loop of :func:`order2_block`; ``stream`` and ``high_degree`` are
    compile-time constants (``literally``).

    Streamed, the chunks go column by column: all u-points of one chunk of v-points,
    then the next chunk.  The row windows of a chunk (a few KiB for every row of the
    table) then stay in L1 while every u-point combines them, where row by row each
    u-point reads its rows' windows from L2; non-temporal stores write whole lines
    whatever their order (1000² partials of a 20x20 NURBS: 17-18 ms against 19-20 ms).
    Plain stores go row by row, along the output, since each of them first reads its
    line (column by column: 41 ms against 36 ms)."""
    literally(stream)
    literally(high_degree)
    acc = np.empty((3, 3, 4, CHUNK))
    planes = acc.reshape(-1)
    flat = out.reshape(-1)
    stride = out.shape[1] * 27
    nv, dim = w.shape[3], 4 if rational else 3
    chunks = (nv + CHUNK - 1) // CHUNK
    outer, inner = (chunks, bu.shape[0]) if stream else (bu.shape[0], chunks)
    for i in range(outer):
        for j in range(inner):
            a, c0 = (j, i * CHUNK) if stream else (i, j * CHUNK)
            n = min(CHUNK, nv - c0)
            if high_degree:
                _combine_chunk_high(bu, a, first[a], p, w, dim, c0, n, acc)
            else:
                _combine_chunk(bu, a, first[a], p, w, dim, c0, n, acc)
            if rational:
                _quotient_chunk(acc, n)
            _store_points(planes, n, flat, a * stride + 27 * (b0 + c0), stream)


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _combine_chunk(bu, a, r0, p, w, dim, c0, n, acc):
    """``acc[k, l, d, :n] = sum_i bu[a, k, i] w[r0 + i, l, d, c0:c0+n]`` up to degree 3,
    as one four-term sum (rows past the degree clamped, their coefficients 0), as in
    :func:`surfmod.eval.grid_kernels._combine_rows`; for each ``(l, d)`` the row windows
    are loaded once for all three ``k``."""
    u0 = uint64(c0)
    r1, r2, r3 = r0 + min(1, p), r0 + min(2, p), r0 + min(3, p)
    c00, c01, c02, c03 = _four(bu, a, 0, p)
    c10, c11, c12, c13 = _four(bu, a, 1, p)
    c20, c21, c22, c23 = _four(bu, a, 2, p)
    for l in range(3):
        for d in range(dim):
            w0, w1, w2, w3 = w[r0, l, d], w[r1, l, d], w[r2, l, d], w[r3, l, d]
            k0, k1, k2 = acc[0, l, d], acc[1, l, d], acc[2, l, d]
            for b in range(n):
                ub = uint64(b)
                x0, x1, x2, x3 = w0[u0 + ub], w1[u0 + ub], w2[u0 + ub], w3[u0 + ub]
                k0[ub] = c00 * x0 + c01 * x1 + c02 * x2 + c03 * x3
                k1[ub] = c10 * x0 + c11 * x1 + c12 * x2 + c13 * x3
                k2[ub] = c20 * x0 + c21 * x1 + c22 * x2 + c23 * x3


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _combine_chunk_high(bu, a, r0, p, w, dim, c0, n, acc):
    """:func:`_combine_chunk` for degrees above 3: the sums of the general path's
    :func:`surfmod.eval.grid_kernels._combine_rows`, term by term."""
    u0 = uint64(c0)
    for k in range(3):
        for l in range(3):
            for d in range(dim):
                dst = acc[k, l, d]
                c = bu[a, k, 0]
                src = w[r0, l, d]
                for b in range(n):
                    dst[uint64(b)] = c * src[u0 + uint64(b)]
                for i in range(1, p + 1):
                    c = bu[a, k, i]
                    src = w[r0 + i, l, d]
                    for b in range(n):
                        dst[uint64(b)] += c * src[u0 + uint64(b)]


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _four(bu, a, k, p):
    """The u-basis row ``bu[a, k]`` padded with zeros to four coefficients."""
    return (bu[a, k, 0], bu[a, k, 1] if p >= 1 else 0.0, bu[a, k, 2] if p >= 2 else 0.0,
            bu[a, k, 3] if p >= 3 else 0.0)


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _quotient_chunk(acc, n):
    """The quotient rule to order 2 in place on the chunk's planes: the terms and their
    order of :func:`surfmod.eval.kernels.quotient_planes`, with each point's weights, their
    doubles (exact) and the reciprocal loaded or formed once for the three coordinates."""
    w00, w01, w02 = acc[0, 0, 3], acc[0, 1, 3], acc[0, 2, 3]
    w10, w11, w12 = acc[1, 0, 3], acc[1, 1, 3], acc[1, 2, 3]
    w20, w21, w22 = acc[2, 0, 3], acc[2, 1, 3], acc[2, 2, 3]
    for b in range(n):
        iw = 1.0 / w00[b]
        v01, v02, v10, v11, v12 = w01[b], w02[b], w10[b], w11[b], w12[b]
        v20, v21, v22 = w20[b], w21[b], w22[b]
        t01, t10, t11, t12, t21, f11 = 2.0 * v01, 2.0 * v10, 2.0 * v11, 2.0 * v12, 2.0 * v21, 4.0 * v11
        for d in range(3):
            s00 = acc[0, 0, d, b] * iw
            s01 = (acc[0, 1, d, b] - v01 * s00) * iw
            s02 = (acc[0, 2, d, b] - t01 * s01 - v02 * s00) * iw
            s10 = (acc[1, 0, d, b] - v10 * s00) * iw
            s11 = (acc[1, 1, d, b] - v01 * s10 - v10 * s01 - v11 * s00) * iw
            s12 = (acc[1, 2, d, b] - t01 * s11 - v02 * s10 - v10 * s02 - t11 * s01 - v12 * s00) * iw
            s20 = (acc[2, 0, d, b] - t10 * s10 - v20 * s00) * iw
            s21 = (acc[2, 1, d, b] - v01 * s20 - t10 * s11 - t11 * s10 - v20 * s01 - v21 * s00) * iw
            s22 = (acc[2, 2, d, b] - t01 * s21 - v02 * s20 - t10 * s12 - f11 * s11 - t12 * s10 - v20 * s02
                   - t21 * s01 - v22 * s00) * iw
            acc[0, 0, d, b], acc[0, 1, d, b], acc[0, 2, d, b] = s00, s01, s02
            acc[1, 0, d, b], acc[1, 1, d, b], acc[1, 2, d, b] = s10, s11, s12
            acc[2, 0, d, b], acc[2, 1, d, b], acc[2, 2, d, b] = s20, s21, s22


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _pair(row, i, x0, x1, stream):
    if stream:
        stream_pair(row, i, x0, x1)
    else:
        row[i] = x0
        row[i + 1] = x1


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_point(planes, b, row, o):
    """Point ``b`` of the chunk's planes to ``row[o:o+27]`` with plain stores."""
    for f in range(27):
        row[o + f] = planes[(f // 3 * 4 + f % 3) * CHUNK + b]


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_points(planes, n, row, o, stream):
    """Points ``0..n-1`` of the chunk (plane ``(k, l, d)`` at ``planes[((3k + l) 4 + d)
    CHUNK:]``) point-major into ``row[o:]``: pairs of points as 27 16-byte stores from
    the first 16-byte boundary on.  A pair's 54 doubles are point ``b``'s 27 then point
    ``b+1``'s, so the pairs are ``(f, f+1)`` of ``b`` for even ``f < 26``, then
    ``(26 of b, 0 of b+1)``, then ``(f, f+1)`` of ``b+1`` for odd ``f``; the loops
    take two entries ``m = 3k + l`` (six doubles, three stores) per step."""
    b = 0
    if n > 0 and not aligned_16(row, o):
        _store_point(planes, 0, row, o)
        b = 1
    d1, d2, d4 = CHUNK, 2 * CHUNK, 4 * CHUNK
    last = 32 * CHUNK  # plane (m = 8, d = 0)
    while b + 1 < n:
        t = o + 27 * b
        for mm in range(4):  # entries m = 2 mm and 2 mm + 1 of point b: doubles 6 mm .. 6 mm + 5
            q = 2 * mm * d4 + b
            _pair(row, t + 6 * mm, planes[q], planes[q + d1], stream)
            _pair(row, t + 6 * mm + 2, planes[q + d2], planes[q + d4], stream)
            _pair(row, t + 6 * mm + 4, planes[q + d4 + d1], planes[q + d4 + d2], stream)
        _pair(row, t + 24, planes[last + b], planes[last + d1 + b], stream)
        _pair(row, t + 26, planes[last + d2 + b], planes[b + 1], stream)
        t += 27
        for mm in range(4):  # doubles 6 mm + 1 .. 6 mm + 6 of point b + 1
            q = 2 * mm * d4 + b + 1
            _pair(row, t + 6 * mm + 1, planes[q + d1], planes[q + d2], stream)
            _pair(row, t + 6 * mm + 3, planes[q + d4], planes[q + d4 + d1], stream)
            _pair(row, t + 6 * mm + 5, planes[q + d4 + d2], planes[q + 2 * d4], stream)
        _pair(row, t + 25, planes[last + d1 + b + 1], planes[last + d2 + b + 1], stream)
        b += 2
    if b < n:
        _store_point(planes, b, row, o + 27 * b)
