"""Compiled (numba) twins of :mod:`surfmod.meshing.gridbounds`, the loops of the
structured-grid verification (:mod:`surfmod.meshing.gridmesh`): per lattice point the
triangles' linear interpolation and a second-order bound of its distance to the surface,
and per cell the maxima.  ``name_compiled`` computes what ``gridbounds.name`` does, into
the caller's arrays.

Imported lazily (numba), compiled once into numba's cache.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always", error_model="numpy")
def _diff(S, A, B, a, K, su, sv, d):
    """Derivative of coordinate ``d`` (times twice the lattice step) at lattice point
    ``(A, B)`` along the lattice step ``(su, sv)`` from the points of its own cell
    (``a``: the point's index in the cell along it): central inside, second-order
    one-sided on the sides, so the stencil never straddles two cells of different sizes."""
    if a == 0:
        return -3.0 * S[A, B, d] + 4.0 * S[A + su, B + sv, d] - S[A + 2 * su, B + 2 * sv, d]
    if a == K:
        return 3.0 * S[A, B, d] - 4.0 * S[A - su, B - sv, d] + S[A - 2 * su, B - 2 * sv, d]
    return S[A + su, B + sv, d] - S[A - su, B - sv, d]


@njit(cache=True, error_model="numpy")
def diagonals_compiled(S, K, diag):
    """Per cell: True for the 00-11 diagonal when its midpoint lies closer to the
    surface's midpoint (along the normal) than the 10-01 one's; ties by 3-D length."""
    ncu, ncv = diag.shape
    h = K // 2
    for i in range(ncu):
        for j in range(ncv):
            a0, a1, b0, b1 = i * K, (i + 1) * K, j * K, (j + 1) * K
            mu, mv = i * K + h, j * K + h
            u0, u1, u2 = (S[mu + 1, mv, 0] - S[mu - 1, mv, 0], S[mu + 1, mv, 1] - S[mu - 1, mv, 1],
                          S[mu + 1, mv, 2] - S[mu - 1, mv, 2])
            v0, v1, v2 = (S[mu, mv + 1, 0] - S[mu, mv - 1, 0], S[mu, mv + 1, 1] - S[mu, mv - 1, 1],
                          S[mu, mv + 1, 2] - S[mu, mv - 1, 2])
            n0 = u1 * v2 - u2 * v1
            n1 = u2 * v0 - u0 * v2
            n2 = u0 * v1 - u1 * v0
            e1 = 0.0
            e2 = 0.0
            l1 = 0.0
            l2 = 0.0
            for d in range(3):
                nd = n0 if d == 0 else (n1 if d == 1 else n2)
                e1 += (S[mu, mv, d] - 0.5 * (S[a0, b0, d] + S[a1, b1, d])) * nd
                e2 += (S[mu, mv, d] - 0.5 * (S[a1, b0, d] + S[a0, b1, d])) * nd
                l1 += (S[a0, b0, d] - S[a1, b1, d]) ** 2
                l2 += (S[a1, b0, d] - S[a0, b1, d]) ** 2
            e1, e2 = abs(e1), abs(e2)
            diag[i, j] = (e1 < e2) or (e1 == e2 and l1 <= l2)


@njit(cache=True, error_model="numpy")
def estimates_compiled(S, K, diag, kmax, est, Q):
    """Linear interpolation ``Q`` of the grid's triangles at every lattice point and the
    bound ``est`` of its distance to the surface: the residual ``S - Q`` minus its
    tangential part (one Gauss-Newton step ``J delta``, the tangents ``J`` by finite
    differences on the cell's own lattice points), plus ``kmax |J delta|^2 / 2``
    for the surface's bending over that step; ``|S - Q|`` where it is smaller or where
    the tangent plane is degenerate (poles)."""
    nlu, nlv = est.shape
    ncu, ncv = diag.shape
    for A in range(nlu):
        I = min(A // K, ncu - 1)
        s = (A - K * I) / K
        for B in range(nlv):
            J = min(B // K, ncv - 1)
            t = (B - K * J) / K
            a0, a1, b0, b1 = I * K, (I + 1) * K, J * K, (J + 1) * K
            for d in range(3):
                p00, p10, p01, p11 = S[a0, b0, d], S[a1, b0, d], S[a0, b1, d], S[a1, b1, d]
                if diag[I, J]:
                    if s >= t:
                        q = p00 + s * (p10 - p00) + t * (p11 - p10)
                    else:
                        q = p00 + t * (p01 - p00) + s * (p11 - p01)
                else:
                    if s + t <= 1.0:
                        q = p00 + s * (p10 - p00) + t * (p01 - p00)
                    else:
                        q = p11 + (1.0 - s) * (p01 - p11) + (1.0 - t) * (p10 - p11)
                Q[A, B, d] = q
            r0, r1, r2 = S[A, B, 0] - Q[A, B, 0], S[A, B, 1] - Q[A, B, 1], S[A, B, 2] - Q[A, B, 2]
            full = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
            ia, jb = A - K * I, B - K * J
            u0, u1, u2 = _diff(S, A, B, ia, K, 1, 0, 0), _diff(S, A, B, ia, K, 1, 0, 1), _diff(S, A, B, ia, K, 1, 0, 2)
            v0, v1, v2 = _diff(S, A, B, jb, K, 0, 1, 0), _diff(S, A, B, jb, K, 0, 1, 1), _diff(S, A, B, jb, K, 0, 1, 2)
            a = u0 * u0 + u1 * u1 + u2 * u2
            b = u0 * v0 + u1 * v1 + u2 * v2
            c = v0 * v0 + v1 * v1 + v2 * v2
            det = a * c - b * b
            if det > 1e-10 * (a + c) * (a + c):
                g1 = u0 * r0 + u1 * r1 + u2 * r2
                g2 = v0 * r0 + v1 * r1 + v2 * r2
                du = (c * g1 - b * g2) / det
                dv = (a * g2 - b * g1) / det
                t0, t1, t2 = du * u0 + dv * v0, du * u1 + dv * v1, du * u2 + dv * v2
                n0, n1, n2 = r0 - t0, r1 - t1, r2 - t2
                e = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2) + 0.5 * kmax * (t0 * t0 + t1 * t1 + t2 * t2)
                est[A, B] = min(e, full)
            else:
                est[A, B] = full


@njit(cache=True, error_model="numpy")
def cell_maxima_compiled(est, K, err, eu, ev):
    """Per cell the largest ``est`` over its lattice points (sides shared with the
    neighbours), and the largest at the midpoints of its u-sides (``eu``) and v-sides
    (``ev``).

    >>> import numpy as np
    >>> est = np.zeros((5, 3)); est[2, 0] = 1.0  # K = 2: 2 x 1 cells; a corner both share
    >>> err, eu, ev = np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1))
    >>> cell_maxima_compiled(est, 2, err, eu, ev)
    >>> err.ravel().tolist(), ev.ravel().tolist(), eu.ravel().tolist()
    ([1.0, 1.0], [0.0, 0.0], [0.0, 0.0])
    """
    nlu, nlv = est.shape
    ncu, ncv = err.shape
    h = K // 2
    err[:] = 0.0
    eu[:] = 0.0
    ev[:] = 0.0
    for A in range(nlu):
        I = min(A // K, ncu - 1)
        a = A - K * I
        for B in range(nlv):
            J = min(B // K, ncv - 1)
            b = B - K * J
            e = est[A, B]
            for di in range(2):
                ii = I - di
                if di == 1 and (a != 0 or ii < 0):
                    continue
                la = K if di == 1 else a
                for dj in range(2):
                    jj = J - dj
                    if dj == 1 and (b != 0 or jj < 0):
                        continue
                    lb = K if dj == 1 else b
                    if e > err[ii, jj]:
                        err[ii, jj] = e
                    if la == h and (lb == 0 or lb == K) and e > eu[ii, jj]:
                        eu[ii, jj] = e
                    if lb == h and (la == 0 or la == K) and e > ev[ii, jj]:
                        ev[ii, jj] = e
