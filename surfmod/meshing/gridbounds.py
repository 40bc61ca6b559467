"""The loops of :mod:`surfmod.meshing.gridbounds_compiled` in NumPy, for lattices too small to
wait for numba: same arithmetic in the same order, so the same values bit for bit (no
``fastmath``).  The lattice ``S`` is ``(ncu K + 1, ncv K + 1, 3)``, ``K`` points per cell and
direction, cells sharing their sides.  See :doc:`/design` (section "The evaluation core").

>>> import numpy as np
>>> S = np.zeros((5, 3, 3)); S[..., 0], S[..., 1] = np.mgrid[0:5, 0:3]  # K = 2: 2 x 1 flat cells
>>> diag = diagonals(S, 2, (2, 1))
>>> est, Q = estimates(S, 2, diag, 0.0)
>>> float(abs(est).max()), bool(np.allclose(Q, S))
(0.0, True)
"""

from __future__ import annotations

import numpy as np


def diagonals(S, K: int, cells: tuple[int, int]) -> np.ndarray:
    """``(ncu, ncv)`` bools as :func:`~surfmod.meshing.gridbounds_compiled.diagonals_compiled`: True for the
    00-11 diagonal when its midpoint lies closer to the surface's midpoint (along the
    normal) than the 10-01 one's; ties by 3-D length."""
    ncu, ncv = cells
    h = K // 2
    mu, mv = np.arange(ncu) * K + h, np.arange(ncv) * K + h
    c0u, c1u, c0v, c1v = mu - h, mu - h + K, mv - h, mv - h + K
    du = S[mu + 1][:, mv] - S[mu - 1][:, mv]
    dv = S[mu][:, mv + 1] - S[mu][:, mv - 1]
    n = [du[..., 1] * dv[..., 2] - du[..., 2] * dv[..., 1], du[..., 2] * dv[..., 0] - du[..., 0] * dv[..., 2],
         du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0]]
    mid = S[mu][:, mv]
    p00, p11 = S[c0u][:, c0v], S[c1u][:, c1v]
    p10, p01 = S[c1u][:, c0v], S[c0u][:, c1v]
    e1 = e2 = l1 = l2 = 0.0
    for d in range(3):
        e1 = e1 + (mid[..., d] - 0.5 * (p00[..., d] + p11[..., d])) * n[d]
        e2 = e2 + (mid[..., d] - 0.5 * (p10[..., d] + p01[..., d])) * n[d]
        l1 = l1 + (p00[..., d] - p11[..., d]) ** 2
        l2 = l2 + (p10[..., d] - p01[..., d]) ** 2
    e1, e2 = np.abs(e1), np.abs(e2)
    return (e1 < e2) | ((e1 == e2) & (l1 <= l2))


def _diff(S, cell_index, K: int, axis: int):
    """Derivatives (times twice the lattice step) along ``axis`` at every lattice point,
    from the points of its own cell: central inside, second-order one-sided on the
    sides (``cell_index``: the point's index within its cell along ``axis``)."""
    size = S.shape[axis]
    idx = np.arange(size)

    def at(offset):
        return np.take(S, np.clip(idx + offset, 0, size - 1), axis=axis)

    shape = [1, 1, 1]
    shape[axis] = size
    a = cell_index.reshape(shape)
    first = -3.0 * S + 4.0 * at(1) - at(2)
    last = 3.0 * S - 4.0 * at(-1) + at(-2)
    return np.where(a == 0, first, np.where(a == K, last, at(1) - at(-1)))


def estimates(S, K: int, diag, kmax: float):
    """``(est, Q)`` as :func:`~surfmod.meshing.gridbounds_compiled.estimates_compiled`: the triangles' linear
    interpolation ``Q`` at every lattice point and the bound ``est`` of its distance to
    the surface (the residual minus its tangential part, plus ``kmax |J delta|^2 / 2``;
    ``|S - Q|`` where that is smaller or the tangent plane is degenerate)."""
    ncu, ncv = diag.shape
    nlu, nlv = S.shape[:2]
    I = np.minimum(np.arange(nlu) // K, ncu - 1)
    J = np.minimum(np.arange(nlv) // K, ncv - 1)
    ia, jb = np.arange(nlu) - K * I, np.arange(nlv) - K * J
    s, t = (ia / K)[:, None, None], (jb / K)[None, :, None]
    a0, a1, b0, b1 = I * K, (I + 1) * K, J * K, (J + 1) * K
    p00, p10 = S[a0][:, b0], S[a1][:, b0]
    p01, p11 = S[a0][:, b1], S[a1][:, b1]
    main = diag[I][:, J][..., None]
    q_main = np.where(s >= t, p00 + s * (p10 - p00) + t * (p11 - p10), p00 + t * (p01 - p00) + s * (p11 - p01))
    q_anti = np.where(s + t <= 1.0, p00 + s * (p10 - p00) + t * (p01 - p00),
                      p11 + (1.0 - s) * (p01 - p11) + (1.0 - t) * (p10 - p11))
    Q = np.where(main, q_main, q_anti)
    r = S - Q
    r0, r1, r2 = r[..., 0], r[..., 1], r[..., 2]
    full = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    du, dv = _diff(S, ia, K, 0), _diff(S, jb, K, 1)
    u0, u1, u2 = du[..., 0], du[..., 1], du[..., 2]
    v0, v1, v2 = dv[..., 0], dv[..., 1], dv[..., 2]
    a = u0 * u0 + u1 * u1 + u2 * u2
    b = u0 * v0 + u1 * v1 + u2 * v2
    c = v0 * v0 + v1 * v1 + v2 * v2
    det = a * c - b * b
    regular = det > 1e-10 * (a + c) * (a + c)
    with np.errstate(divide="ignore", invalid="ignore"):
        g1 = u0 * r0 + u1 * r1 + u2 * r2
        g2 = v0 * r0 + v1 * r1 + v2 * r2
        step_u = (c * g1 - b * g2) / det
        step_v = (a * g2 - b * g1) / det
        t0, t1, t2 = step_u * u0 + step_v * v0, step_u * u1 + step_v * v1, step_u * u2 + step_v * v2
        n0, n1, n2 = r0 - t0, r1 - t1, r2 - t2
        e = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2) + 0.5 * kmax * (t0 * t0 + t1 * t1 + t2 * t2)
    # min(e, full) as the kernel takes it: e unless full < e (so a NaN e stays)
    return np.where(regular & ~(full < e), e, full), Q


def cell_maxima(est, K: int, cells: tuple[int, int]):
    """``(err, eu, ev)`` as :func:`~surfmod.meshing.gridbounds_compiled.cell_maxima_compiled`: per cell the
    largest ``est`` over its lattice points (sides shared with the neighbours), and the
    largest at the midpoints of its u-sides and v-sides; 0 at least (NaN is skipped)."""
    ncu, ncv = cells
    h = K // 2
    rows = np.fmax.reduce([est[a : a + ncu * K : K] for a in range(K + 1)])  # (ncu, nlv)
    err = np.fmax.reduce([rows[:, b : b + ncv * K : K] for b in range(K + 1)])
    mid_u, mid_v = np.arange(ncu) * K + h, np.arange(ncv) * K + h
    side_u, side_v = np.arange(ncu + 1) * K, np.arange(ncv + 1) * K
    at_u = est[mid_u][:, side_v]  # u-side midpoints: (ncu, ncv + 1)
    at_v = est[side_u][:, mid_v]  # (ncu + 1, ncv)
    eu = np.fmax(at_u[:, :-1], at_u[:, 1:])
    ev = np.fmax(at_v[:-1], at_v[1:])
    return tuple(np.fmax(x, 0.0) for x in (err, eu, ev))
