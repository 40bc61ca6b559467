"""Second stage of the grid for partials to order 2 (the 27 doubles a point of
``(n_u, N_v, 3, 3, 3)``), in chunks of :data:`CHUNK` v-points that stay in L1.

For each u-point and chunk: its p+1 rows of the row table are combined into 36 planes
(partial ``(k, l)``, coordinate ``d``; each row window loaded once for all three ``k``),
the quotient rule runs over the chunk with each point's weights and their multiples
loaded once for the three coordinates, and each pair of points (54 doubles) goes to the
output as 27 16-byte pairs of doubles.  Done plane by plane over a whole v-row (the
general path of :func:`surfmod.eval.grid_kernels.grid_derivatives`), the same work moves
every plane through L2 three times; here only the row table is read from L2.

Every value is the same sum, in the same order, as in the general path, compiled with
fused multiply-adds (``fastmath={"contract"}``, nothing else): one rounding per term
instead of two, so the results equal the general path's to rounding (a few ulps of each
partial's size, ``tests/test_eval_partials_stage.py``) and are deterministic (the same on
one thread or several, for any blocking).
"""

from __future__ import annotations

import numpy as np
from numba import literally, njit, uint64

from .kernels import quotient_order2

#: v-points per chunk: 36 planes of 16 doubles (4.6 KiB) beside the row windows in L1
CHUNK = 16
#: doubles of one chunk's planes: plane ``(k, l, d)`` at ``((3 k + l) 4 + d) CHUNK``
PLANES = 36 * CHUNK


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def order2_block(bu, first, p, w, rational, b0, out):
    """Partials to order 2 of a block of u-points: ``out[a, b0:b0+n_v]`` from the row
    table ``w (rows, 3, dim, n_v)``, ``first[a]`` the place of u-point ``a``'s first row
    in it, ``bu (n_u, 3, p+1)`` the u-basis with its derivatives."""
    # one compiled chunk loop per combine: each holds only its own hot loop (measured:
    # with two in one function, LLVM compiled them to half the speed)
    planes = np.empty(PLANES)
    if p <= 3:
        _chunks(bu, first, p, w, rational, b0, out, planes, False)
    else:
        _chunks(bu, first, p, w, rational, b0, out, planes, True)


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _chunks(bu, first, p, w, rational, b0, out, planes, high_degree):
    """The chunk loop of :func:`order2_block`, one chunk at a time in ``planes``, row by
    row along the output; ``high_degree`` is a compile-time constant (``literally``)."""
    literally(high_degree)
    flat = out.reshape(-1)
    stride = out.shape[1] * 27
    nv, dim = w.shape[3], 4 if rational else 3
    chunks = (nv + CHUNK - 1) // CHUNK
    for a in range(bu.shape[0]):
        for j in range(chunks):
            c0 = j * CHUNK
            n = min(CHUNK, nv - c0)
            if high_degree:
                _combine_high(bu, a, first[a], p, w, dim, c0, n, planes, 0)
            else:
                _combine(bu, a, first[a], p, w, dim, c0, n, planes, 0)
            if rational:
                _quotient(planes, 0, 0, n)
            _store_points(planes, 0, n, flat, a * stride + 27 * (b0 + c0))


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _combine(bu, a, r0, p, w, dim, c0, n, planes, base):
    """Plane ``(k, l, d)`` of the chunk at ``planes[base:]``, points ``:n``: ``sum_i
    bu[a, k, i] w[r0 + i, l, d, c0:c0+n]`` up to degree 3, as one four-term sum (rows
    past the degree clamped, their coefficients 0), as in
    :func:`surfmod.eval.grid_kernels._combine_rows`; for each ``(l, d)`` the row windows
    are loaded once for all three ``k``.  Unsigned offsets into the one flat array: no
    wraparound selects, and few runtime alias checks before LLVM vectorizes."""
    u0 = uint64(c0)
    r1, r2, r3 = r0 + min(1, p), r0 + min(2, p), r0 + min(3, p)
    c00, c01, c02, c03 = _four(bu, a, 0, p)
    c10, c11, c12, c13 = _four(bu, a, 1, p)
    c20, c21, c22, c23 = _four(bu, a, 2, p)
    for l in range(3):
        for d in range(dim):
            w0, w1, w2, w3 = w[r0, l, d], w[r1, l, d], w[r2, l, d], w[r3, l, d]
            q0 = uint64(base + (l * 4 + d) * CHUNK)
            q1, q2 = q0 + uint64(12 * CHUNK), q0 + uint64(24 * CHUNK)
            for b in range(n):
                ub = uint64(b)
                x0, x1, x2, x3 = w0[u0 + ub], w1[u0 + ub], w2[u0 + ub], w3[u0 + ub]
                planes[q0 + ub] = c00 * x0 + c01 * x1 + c02 * x2 + c03 * x3
                planes[q1 + ub] = c10 * x0 + c11 * x1 + c12 * x2 + c13 * x3
                planes[q2 + ub] = c20 * x0 + c21 * x1 + c22 * x2 + c23 * x3


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _combine_high(bu, a, r0, p, w, dim, c0, n, planes, base):
    """:func:`_combine` for degrees above 3: the sums of the general path's
    :func:`surfmod.eval.grid_kernels._combine_rows`, term by term."""
    u0 = uint64(c0)
    for k in range(3):
        for l in range(3):
            for d in range(dim):
                q = uint64(base + ((3 * k + l) * 4 + d) * CHUNK)
                c = bu[a, k, 0]
                src = w[r0, l, d]
                for b in range(n):
                    planes[q + uint64(b)] = c * src[u0 + uint64(b)]
                for i in range(1, p + 1):
                    c = bu[a, k, i]
                    src = w[r0 + i, l, d]
                    for b in range(n):
                        planes[q + uint64(b)] += c * src[u0 + uint64(b)]


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _four(bu, a, k, p):
    """The u-basis row ``bu[a, k]`` padded with zeros to four coefficients."""
    return (bu[a, k, 0], bu[a, k, 1] if p >= 1 else 0.0, bu[a, k, 2] if p >= 2 else 0.0,
            bu[a, k, 3] if p >= 3 else 0.0)


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _quotient(planes, base, lo, hi):
    """The quotient rule to order 2 (:func:`surfmod.eval.kernels.quotient_order2`) in
    place on points ``lo:hi`` of the chunk at ``planes[base:]``, with each point's
    weights and their reciprocal loaded or formed once for the three coordinates."""
    c = CHUNK
    for b in range(lo, hi):
        i = uint64(base + b)
        iw = 1.0 / planes[i + uint64(3 * c)]
        v01, v02 = planes[i + uint64(7 * c)], planes[i + uint64(11 * c)]
        v10, v11, v12 = planes[i + uint64(15 * c)], planes[i + uint64(19 * c)], planes[i + uint64(23 * c)]
        v20, v21, v22 = planes[i + uint64(27 * c)], planes[i + uint64(31 * c)], planes[i + uint64(35 * c)]
        for d in range(3):
            j = i + uint64(d * c)
            j01, j02, j10, j11 = j + uint64(4 * c), j + uint64(8 * c), j + uint64(12 * c), j + uint64(16 * c)
            j12, j20, j21, j22 = j + uint64(20 * c), j + uint64(24 * c), j + uint64(28 * c), j + uint64(32 * c)
            (planes[j], planes[j01], planes[j02], planes[j10], planes[j11], planes[j12], planes[j20], planes[j21],
             planes[j22]) = quotient_order2(planes[j], planes[j01], planes[j02], planes[j10], planes[j11], planes[j12],
                                            planes[j20], planes[j21], planes[j22], iw, v01, v02, v10, v11, v12, v20,
                                            v21, v22)


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _two(row, i, x0, x1):
    row[i] = x0
    row[i + uint64(1)] = x1


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_point(planes, q, row, o):
    """The point at ``planes[q]`` (plane offsets from there) to ``row[o:o+27]`` with
    plain stores."""
    for f in range(27):
        row[uint64(o + f)] = planes[uint64(q + (f // 3 * 4 + f % 3) * CHUNK)]


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_pair(planes, q, row, t):
    """The points at ``planes[q]`` and ``planes[q + 1]`` (plane offsets from there) to
    ``row[t:t+54]``, as 27 pairs of doubles (which LLVM may store 16 bytes at a time).  A pair's
    54 doubles are the first point's 27 then the second's, so the pairs are ``(f, f+1)``
    of the first for even ``f < 26``, then ``(26 of the first, 0 of the second)``, then
    ``(f, f+1)`` of the second for odd ``f``; the loops take two entries ``m = 3k + l``
    (six doubles, three stores) per step."""
    b, s, one = uint64(q), uint64(t), uint64(1)
    d1, d2, d4 = uint64(CHUNK), uint64(2 * CHUNK), uint64(4 * CHUNK)
    last = uint64(32 * CHUNK)  # plane (m = 8, d = 0)
    for mm in range(4):  # entries m = 2 mm and 2 mm + 1 of the first point: doubles 6 mm .. 6 mm + 5
        e = uint64(2 * mm) * d4 + b
        u = s + uint64(6 * mm)
        _two(row, u, planes[e], planes[e + d1])
        _two(row, u + uint64(2), planes[e + d2], planes[e + d4])
        _two(row, u + uint64(4), planes[e + d4 + d1], planes[e + d4 + d2])
    _two(row, s + uint64(24), planes[last + b], planes[last + d1 + b])
    _two(row, s + uint64(26), planes[last + d2 + b], planes[b + one])
    s += uint64(27)
    for mm in range(4):  # doubles 6 mm + 1 .. 6 mm + 6 of the second point
        e = uint64(2 * mm) * d4 + b + one
        u = s + uint64(6 * mm)
        _two(row, u + one, planes[e + d1], planes[e + d2])
        _two(row, u + uint64(3), planes[e + d4], planes[e + d4 + d1])
        _two(row, u + uint64(5), planes[e + d4 + d2], planes[e + d4 + d4])
    _two(row, s + uint64(25), planes[last + d1 + b + one], planes[last + d2 + b + one])


@njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _store_points(planes, base, n, row, o):
    """Points ``0..n-1`` of the chunk at ``planes[base:]`` point-major into ``row[o:]``,
    in pairs of points (:func:`_store_pair`)."""
    b = 0
    while b + 1 < n:
        _store_pair(planes, base + b, row, o + 27 * b)
        b += 2
    if b < n:
        _store_point(planes, base + b, row, o + 27 * b)
