"""Tensor-product surface evaluation with local support: each point touches only its
``(p+1) x (q+1)`` poles, so the cost depends on the points and the degrees, not on the
size of the control net (a 1000 x 1000 net costs what a 4 x 4 one does).

Scattered pairs run one compiled loop over the points (span search, basis derivatives,
local contraction, quotient rule).  Grids run in two stages: the net rows that the
u-points need are contracted with the v-basis once (``W[i, l, :, b]``), then each u-point
combines its p+1 rows with the v-points on the contiguous axis.  The u-points go in
blocks so that the row table stays a few MiB whatever the grid or the net.

The compiled kernels live in :mod:`surfmod.eval.kernels`, imported on first use (so
``import surfmod`` does not load numba).

>>> import numpy as np
>>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> surface_points(prepare(knots, 3, knots, 3, net), np.array([0.5]), np.array([0.25]))
array([[1.5 , 0.75, 0.  ]])
"""

from __future__ import annotations

import numpy as np

from typing import NamedTuple

from .basis import basis_derivatives, find_spans

#: doubles in the per-block row table of the grid stage (4 MiB): fits in L2/L3
ROW_TABLE = 1 << 19
#: v-points per block of the grid: the rows a u-point combines stay in cache
V_BLOCK = 1024


def _kernels():
    from . import kernels  # numba: compiled on first use, then from its disk cache

    return kernels


def writable(t) -> np.ndarray:
    """A flat, C-contiguous, writable float64 array (copied only when needed): one
    array type for the compiled kernels, so they are compiled once."""
    return np.require(np.asarray(t, dtype=float).ravel(), float, ["C", "W"])


_as_float = writable


class LocalNet(NamedTuple):
    """A surface's data as the kernels take it, built once per surface by :func:`prepare`."""

    knots_u: np.ndarray
    p: int
    knots_v: np.ndarray
    q: int
    ctrl: np.ndarray  # (n, m, 4), see homogeneous4
    rational: bool
    inv_u: np.ndarray  # reciprocal knot differences (kernels.reciprocal_table)
    inv_v: np.ndarray
    bucket_u: tuple  # span search buckets (kernels.span_buckets)
    bucket_v: tuple
    cache: dict  # tables built on first need (the per-span patches of eval/patches.py)


def prepare(knots_u, p: int, knots_v, q: int, hctrl: np.ndarray) -> LocalNet:
    """Tables for the kernels from full knot vectors, degrees and the homogeneous net
    ``(n, m, 3)`` (polynomial) or ``(n, m, 4)`` (rational)."""
    k = _kernels()
    ku, kv = writable(knots_u), writable(knots_v)
    ctrl = homogeneous4(hctrl)
    n, m = ctrl.shape[:2]
    return LocalNet(ku, int(p), kv, int(q), ctrl, hctrl.shape[-1] == 4,
                    k.reciprocal_table(ku, p, n), k.reciprocal_table(kv, q, m),
                    k.span_buckets(ku, p, n), k.span_buckets(kv, q, m), {})


def positions_finite(net: LocalNet) -> bool:
    """Whether every position of the surface is finite whatever the parameters: a point
    is a convex combination of the control points (non-negative basis functions, positive
    weights), so finite homogeneous sums that cannot overflow (``|h| < 1e300``) and a
    weight sum that cannot underflow to zero (every weight above ``1e-290``) prove it.
    Checked once per net; callers then skip the pass over the output.

    >>> import numpy as np
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
    >>> positions_finite(prepare(knots, 3, knots, 3, net))
    True
    """
    known = net.cache.get("positions_finite")
    if known is None:
        h = net.ctrl
        known = bool(np.isfinite(h).all() and np.abs(h).max() < 1e300
                     and (not net.rational or h[..., 3].min() > 1e-290))
        net.cache["positions_finite"] = known
    return known


#: scattered points per span pair from which the per-span patch table pays for itself
PATCH_POINTS_PER_SPAN = 8
#: and at least this many points
PATCH_MIN_POINTS = 4096


def _patch_table(net: LocalNet, count: int):
    """The per-span patch table (eval/patches.py) when it suits the net and ``count``
    points, built once per net; else None."""
    table = net.cache.get("patches")
    if table is not None:
        return table
    n, m = net.ctrl.shape[:2]
    if count < max(PATCH_MIN_POINTS, PATCH_POINTS_PER_SPAN * (n - net.p) * (m - net.q)):
        return None
    from . import patches

    if not patches.suits(net.p, net.q, n, m):
        return None
    table = net.cache["patches"] = patches.build(net)
    return table


def surface_points(net: LocalNet, u, v, out=None) -> np.ndarray:
    """Positions at scattered pairs ``(u[a], v[a])``: ``(N, 3)``, written into ``out`` when
    given (any C-contiguous ``(N, 3)`` float array, e.g. a slice of a larger buffer).

    Many points on a small low-degree net go through per-span polynomial patches
    (:mod:`surfmod.eval.patches`), the others through the basis-function kernel."""
    k = _kernels()
    u, v = _as_float(u), _as_float(v)
    if out is None:
        out = np.empty((u.size, 3))
    table = _patch_table(net, u.size)
    if table is not None:
        from . import patches

        patches.positions(net, table, u, v, out)
        return out
    k.scattered_positions(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, u, v, net.rational,
                          net.inv_u, net.inv_v, net.bucket_u, net.bucket_v, out)
    return out


def surface_derivatives(net: LocalNet, u, v, order: int, out=None) -> np.ndarray:
    """Cartesian mixed partials at scattered pairs: ``(N, K, K, 3)``, ``K = order + 1``;
    entry ``[a, k, l]`` is d^(k+l) S / du^k dv^l (the rational quotient rule included)."""
    k = _kernels()
    u, v = _as_float(u), _as_float(v)
    if out is None:
        out = np.empty((u.size, order + 1, order + 1, 3))
    k.scattered_derivatives(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, u, v, int(order), net.rational,
                            k.binomials(order), net.inv_u, net.inv_v, net.bucket_u, net.bucket_v, out)
    return out


def _basis(knots, degree, n_ctrl, t, order):
    spans = find_spans(knots, degree, n_ctrl, t)
    ders = np.ascontiguousarray(basis_derivatives(knots, degree, spans, t, order))  # (N, K, deg+1)
    return spans, ders


def homogeneous4(ctrl: np.ndarray) -> np.ndarray:
    """The net as ``(n, m, 4)`` float64, C-contiguous: homogeneous points stay, a
    polynomial net gets a unit weight column (the kernels' inner loop is a 4-vector)."""
    if ctrl.shape[-1] == 4:
        return np.require(ctrl, float, ["C", "W"])
    out = np.ones(ctrl.shape[:-1] + (4,))
    out[..., :3] = ctrl
    return out


def _row_blocks(su, p, n, per_row):
    """Blocks of u-points whose net rows fit the row table: ``(a0, a1, rows, first)``."""
    max_rows = max(p + 1, ROW_TABLE // max(1, per_row))
    step = max(1, su.size) if n <= max_rows else max(1, max_rows // (p + 1))
    for a0 in range(0, su.size, step):  # loop over memory blocks, not points
        s = su[a0 : a0 + step]
        rows = np.unique((s[:, None] - p + np.arange(p + 1)).ravel())
        yield a0, a0 + s.size, rows, np.searchsorted(rows, s - p)


def surface_grid(net: LocalNet, us, vs, order: int, out=None) -> np.ndarray:
    """Cartesian mixed partials on the grid ``us x vs``: ``(len(us), len(vs), K, K, 3)``.

    Positions (``order == 0``) are written point-major, into ``out (len(us), len(vs), 3)``
    when given.  Partials are written planar (every partial and coordinate a contiguous
    row of v) and returned as the transposed view, or, when ``out (len(us), len(vs), K,
    K, 3)`` is given, point-major into it (the caller's array is filled and returned).
    """
    k = _kernels()
    knots_u, p, knots_v, q, ctrl, rational = net[:6]
    us, vs = _as_float(us), _as_float(vs)
    n, m = ctrl.shape[:2]
    kk = order + 1
    dim = 4 if rational else 3
    su, bu = _basis(knots_u, p, n, us, order)
    sv, bv = _basis(knots_v, q, m, vs, order)
    acc = np.empty((kk, kk, 4, min(V_BLOCK, vs.size)))
    if order == 0:
        if out is None:
            out = np.empty((us.size, vs.size, 3))
    else:
        binom = k.binomials(order)
        if out is None:
            planar = np.empty((us.size, kk, kk, 3, vs.size))
    for b0 in range(0, vs.size, V_BLOCK):  # loop over cache blocks, not points
        svb, bvb = sv[b0 : b0 + V_BLOCK], bv[b0 : b0 + V_BLOCK]
        accb = acc if svb.size == acc.shape[-1] else np.empty(acc.shape[:-1] + (svb.size,))
        for a0, a1, rows, first in _row_blocks(su, p, n, kk * dim * svb.size):
            table = np.empty((rows.size, kk, dim, svb.size))
            k.grid_rows(bvb, svb, q, ctrl, rows, dim, table)
            if order == 0:
                k.grid_positions(bu[a0:a1], first, p, table, rational, accb, b0, out[a0:a1])
            elif out is not None:
                k.grid_derivatives_point_major(bu[a0:a1], first, p, table, rational, binom, accb, b0, out[a0:a1])
            else:
                k.grid_derivatives(bu[a0:a1], first, p, table, rational, binom, accb, b0, planar[a0:a1])
    if order == 0:
        return out[:, :, None, None, :]
    return out if out is not None else planar.transpose(0, 4, 1, 2, 3)
