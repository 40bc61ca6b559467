"""Tensor-product surface evaluation with local support, the one entry of the eval core
(:func:`prepare`, :func:`surface_points`, :func:`surface_derivatives`, :func:`surface_grid`).

The amount of work picks the NumPy twin or the compiled one (:func:`_scattered`,
:func:`surface_grid`; :func:`numpy_only` for a caller that counted a small task up front),
:func:`_kernel` the compiled twin and its threads; the compiled modules are imported on
first use, so ``import surfmod`` does not load numba.  See :doc:`/design_eval`.

>>> import numpy as np
>>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> surface_points(prepare(knots, 3, knots, 3, net), np.array([0.5]), np.array([0.25]))
array([[1.5 , 0.75, 0.  ]])
"""

from __future__ import annotations

import threading
import warnings
from contextlib import contextmanager, nullcontext
from math import comb
from typing import NamedTuple

import numpy as np

from . import derivative_nets
from .basis import reciprocal_table, span_buckets
from .rational import surface_quotient
from .scattered import basis_at, scattered
from .tensor_grid import tensor_grid
from .threads import numba_threads, running_on, threads_for

#: rows in the ring of contracted net rows at least: a pass reads at most five (a cubic
#: pair of positions on rows shifted by one), a u-point of degree p reads p + 1
RING_ROWS = 8
#: v-points a chunk of the ring covers at most: each net row's coordinate planes are
#: then read in long contiguous stretches, which the hardware prefetchers follow from
#: memory (chunks of 256 made 1000² positions on a 1000 x 1000 net 20 % slower)
CHUNK = 1024
#: the same for partials (or positions above degree 3), whose ring rows hold K planes
#: each: the ring stays within 1 MiB (order 2, rational: 8 x 3 x 4 x 1024 doubles, 768 KiB)
RING_DOUBLES = 1 << 17
#: fewest u-points per block when blocks are split among threads
GRID_MIN_BLOCK = 16
#: blocks per thread (at least): threads that finish early take more of them
BLOCKS_PER_THREAD = 8
#: work (points times partials per point, ``(order + 1)^2``) from which scattered pairs
#: go through the compiled kernels; less is done in NumPy (:mod:`surfmod.eval.scattered`),
#: which takes milliseconds there, while the first compiled call of a process loads numba
#: and its kernels (about a second; minutes into an empty cache)
COMPILED_SCATTERED = 1 << 15
#: the same for grids, whose NumPy path costs less per point (one row stage for all u):
#: below it, less than loading the grid kernels; the meshers' and the gallery's grids stay
#: below it, so a first `surfmod gallery` compiles no grid stage (design_eval.md,
#: "Start-up, measured")
COMPILED_GRID = 3 << 18


_TASK = threading.local()


@contextmanager
def numpy_only():
    """Scattered pairs evaluated inside the block run in NumPy whatever their number: for
    a task its caller has counted up front and found small as a whole (the measure of a
    small part's mesh, :data:`surfmod.meshing.brep.COMPILED_MEASURE`), where one piece
    past :data:`COMPILED_SCATTERED` would make a fresh process load numba and a kernel
    (about a second) for what NumPy does in a fraction of that."""
    before = getattr(_TASK, "numpy", False)
    _TASK.numpy = True
    try:
        yield
    finally:
        _TASK.numpy = before


def _kernels():
    from . import kernels  # numba: compiled on first use, then from its disk cache

    return kernels


def _kernel(name: str, points: int):
    """The compiled twin ``name`` for ``points`` evaluations and its thread count:
    ``name_compiled`` on one thread, or ``name_parallel`` (:mod:`surfmod.eval.parallel`,
    equal bit for bit) when :mod:`surfmod.eval.threads` allows several threads.  The
    modules are imported here, on first use (numba: compiled once, then from its disk cache)."""
    count = threads_for(points)
    if count > 1:
        from . import parallel

        return getattr(parallel, f"{name}_parallel"), count
    if name == "tensor_grid":
        from . import tensor_grid_compiled as module
    elif name.startswith("patch_"):
        from . import patches as module
    else:
        from . import scattered_compiled as module
    return getattr(module, f"{name}_compiled"), 1


def _on(count: int):
    """The ``with`` context that runs numba's parallel kernels on ``count`` threads."""
    return running_on(count) if count > 1 else nullcontext()


def writable(t) -> np.ndarray:
    """A flat, C-contiguous, writable float64 array (copied only when needed): one
    array type for the compiled kernels, so they are compiled once.  The kernels only
    read it; a view from ``np.broadcast_arrays`` is passed as it is (NumPy warns that it
    will turn such views read-only, in which case ``np.require`` copies them)."""
    if type(t) is np.ndarray and t.dtype == np.float64 and t.ndim == 1:
        flags = t.flags  # own data first: reading .writeable of a broadcast view warns
        if flags.c_contiguous and flags.owndata and flags.writeable:
            return t  # the common case, without the cost of catching warnings
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "future versions will not create a writeable array", FutureWarning)
        return np.require(np.asarray(t, dtype=float).ravel(), float, ["C", "W"])


class LocalNet(NamedTuple):
    """A surface's data as the kernels take it, built once per surface by :func:`prepare`."""

    knots_u: np.ndarray
    p: int
    knots_v: np.ndarray
    q: int
    ctrl: np.ndarray  # (n, m, 4), see homogeneous4
    rational: bool
    inv_u: np.ndarray  # reciprocal knot differences (basis.reciprocal_table)
    inv_v: np.ndarray
    bucket_u: tuple  # span search buckets (basis.span_buckets)
    bucket_v: tuple
    cache: dict  # tables built on first need (the per-span patches of eval/patches.py)
    origin: np.ndarray | None = None  # the point the evaluated net is taken about (see prepare)


#: a net whose centre lies farther from the origin than this many times its radius is
#: evaluated about its centre (see :func:`prepare`)
FAR_NET = 1.0


def prepare(knots_u, p: int, knots_v, q: int, hctrl: np.ndarray, points=None, weights=None) -> LocalNet:
    """Tables for the kernels from full knot vectors, degrees and the homogeneous net
    ``(n, m, 3)`` (polynomial) or ``(n, m, 4)`` (rational).

    Given the Cartesian ``points`` (and ``weights``) of a net far from the origin (its
    centre more than :data:`FAR_NET` radii away), the evaluators take the net less its
    centre and add the centre back to the positions.  A derivative is a sum of poles
    weighted by basis derivatives that cancel (they sum to zero), so it carries a
    rounding error of ``eps`` times the poles' magnitude: a 100 mm face 1e6 mm from the
    origin lost four digits of its partials (OCCT loses them too).  About the centre the
    magnitude is the net's radius.  ``ctrl`` stays the net itself (the projection and
    Newton kernels compare it with points in space); the centred copy is in ``cache``.
    """
    ku, kv = writable(knots_u), writable(knots_v)
    ctrl = homogeneous4(hctrl)
    n, m = ctrl.shape[:2]
    net = LocalNet(ku, int(p), kv, int(q), ctrl, hctrl.shape[-1] == 4,
                   reciprocal_table(ku, p, n), reciprocal_table(kv, q, m),
                   span_buckets(ku, p, n), span_buckets(kv, q, m), {})
    centre = None if points is None else far_centre(points)
    if points is not None and weights is not None:  # the derivative nets difference them
        net.cache["cartesian"] = (np.asarray(points, float), np.asarray(weights, float))
    if centre is not None:
        net.cache["centred"] = net._replace(ctrl=homogeneous4(moved_homogeneous(points, weights, centre)), cache={},
                                            origin=centre)
    return net


def far_centre(points) -> np.ndarray | None:
    """The centre of the bounding box of ``points`` (``(..., 3)``) when it lies farther
    from the origin than :data:`FAR_NET` times the box's half size (a net whose
    derivatives lose digits to its distance, see :func:`prepare`), else None.

    >>> far_centre([(1e6, 0, 0), (1e6 + 2, 2, 0)]).tolist(), far_centre([(-1, 0, 0), (2, 1, 0)])
    ([1000001.0, 1.0, 0.0], None)
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    with np.errstate(over="ignore", invalid="ignore"):  # nets near the float range stay as they are
        centre = 0.5 * lo + 0.5 * hi
        far = np.abs(centre).max() > FAR_NET * 0.5 * (hi - lo).max()
    return centre if far else None


def moved_homogeneous(points, weights, centre) -> np.ndarray:
    """The homogeneous net of ``points - centre`` (with ``weights``, if any), made from the
    Cartesian poles: ``w P - w c`` would keep the rounding of ``w P``."""
    moved = np.asarray(points, dtype=float) - centre
    if weights is None:
        return moved
    w = np.asarray(weights, dtype=float)[..., None]
    return np.concatenate([moved * w, w], axis=-1)


def _centred(net: LocalNet) -> LocalNet:
    """The net the evaluators take: about its centre when :func:`prepare` moved it."""
    return net.cache.get("centred", net)


def _add_origin(net: LocalNet, positions: np.ndarray) -> None:
    """Positions of a centred net back in place (nothing for a net left where it was)."""
    if net.origin is not None:
        positions += net.origin


def partials_finite(net: LocalNet, order: int) -> bool:
    """Whether every partial up to ``order`` (0: the positions) is finite whatever the
    parameters, by a bound computed once per net and order; callers then skip the pass
    over the output.

    A k-th derivative of a degree-p basis function is at most ``(2 p / d)^k`` in
    magnitude (``d`` the shortest non-empty knot span: eq. 2.9 of The NURBS Book applied
    k times), the basis functions sum to one, and the weight sum is at least the smallest
    weight.  So the homogeneous partials, the weight partials and, through the quotient
    rule, the Cartesian ones have explicit bounds; below ``1e290`` nothing overflows, and
    weights above ``1e-290`` keep the denominator from underflowing to zero.

    >>> import numpy as np
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
    >>> partials_finite(prepare(knots, 3, knots, 3, net), 2)
    True
    """
    key = ("partials_finite", order)
    known = net.cache.get(key)
    if known is None:
        bound = partial_bounds(net, order)
        known = net.cache[key] = bool(bound is not None and np.all(bound < 1e290))
    return known


def partial_bounds(net: LocalNet, order: int):
    """``(K, K)`` upper bounds of the magnitudes of the Cartesian partials (see
    :func:`partials_finite`), or None for a net with a non-finite pole or a weight at or
    below ``1e-290``."""
    h = net.ctrl
    if not np.isfinite(h).all():
        return None
    w_min = float(h[..., 3].min()) if net.rational else 1.0
    if not w_min > 1e-290:
        return None
    kk = order + 1
    (ku, p), (kv, q) = (net.knots_u, net.p), (net.knots_v, net.q)

    def steps(knots, degree):  # (2 p / d)^k for k = 0..order, d the shortest non-empty span
        gaps = np.diff(knots)
        rate = 2.0 * degree / gaps[gaps > 0].min()
        return rate ** np.arange(kk, dtype=float)

    with np.errstate(over="ignore", invalid="ignore"):
        growth = np.outer(steps(ku, p), steps(kv, q)) * (p + 1) * (q + 1)
        a_bound = growth * float(np.abs(h[..., :3]).max())
        if not net.rational:
            return a_bound
        w_bound = growth * float(h[..., 3].max())
        bound = np.zeros((kk, kk))
        for k in range(kk):  # the quotient rule (A4.4) on magnitudes, entry by entry
            for l in range(kk):
                acc = a_bound[k, l]
                for i in range(k + 1):
                    for j in range(l + 1):
                        if i or j:
                            acc += comb(k, i) * comb(l, j) * w_bound[i, j] * bound[k - i, l - j]
                bound[k, l] = acc / (0.5 * w_min)
        # the weight partials are summed too: they must not overflow either
        return np.where(w_bound < 1e290, bound, np.inf)


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

    if not patches.suits(net.p, net.q, n, m, net.ctrl[..., 3] if net.rational else None, (net.knots_u, net.knots_v)):
        return None
    table = net.cache["patches"] = patches.build_table(net)
    return table


def surface_points(net: LocalNet, u, v, out=None) -> np.ndarray:
    """Positions at scattered pairs ``(u[a], v[a])``: ``(N, 3)``, written into ``out`` when
    given (any C-contiguous ``(N, 3)`` float array, e.g. a slice of a larger buffer).

    Many points on a small low-degree net go through per-span polynomial patches
    (:mod:`surfmod.eval.patches`), the others through the basis-function kernel."""
    return _scattered(net, u, v, 0, True, out)


def surface_derivatives(net: LocalNet, u, v, order: int, out=None) -> np.ndarray:
    """Cartesian mixed partials at scattered pairs: ``(N, K, K, 3)``, ``K = order + 1``;
    entry ``[a, k, l]`` is d^(k+l) S / du^k dv^l (the rational quotient rule included).

    Partials to order 1 or 2 of many points on a small low-degree net go through the
    per-span patches (:mod:`surfmod.eval.patches`, as positions do), the others through
    the basis-function kernel."""
    return _scattered(net, u, v, order, False, out)


def _scattered(net: LocalNet, u, v, order: int, positions: bool, out) -> np.ndarray:
    """The one place scattered pairs pick their path: NumPy (:func:`scattered`) below
    :data:`COMPILED_SCATTERED` partials or inside :func:`numpy_only`, else the per-span
    patches (positions, or partials to order 1 or 2, on a net that suits them), else the
    basis-function kernel;
    a compiled one on the threads :func:`_kernel` picks.  ``positions``: ``(N, 3)``
    positions instead of ``(N, K, K, 3)`` partials.  Partials of a net with crowded
    knots come from its derivative nets (:func:`_from_derivative_nets`)."""
    u, v = writable(u), writable(v)
    if not positions and order > 0 and _crowded(net):
        return _store(_from_derivative_nets(net, order, lambda d: surface_points(d, u, v)), out)
    net = _centred(net)
    if u.size * (order + 1) ** 2 < COMPILED_SCATTERED or getattr(_TASK, "numpy", False):
        h = scattered(*net[:4], net.ctrl, net.rational, u, v, order)
        _add_origin(net, h[:, 0, 0])
        return _store(h[:, 0, 0] if positions else h, out)
    if out is None:
        out = np.empty((u.size, 3) if positions else (u.size, order + 1, order + 1, 3))
    table = _patch_table(net, u.size) if positions or order in (1, 2) else None
    if table is not None:  # the kernels add the origin as they store
        from . import patches

        run, count = _kernel("patch_positions" if positions else "patch_derivatives", u.size)
        with _on(count):
            run(*patches.arguments(net, table, u, v, out), net.origin)
        return out
    head, tail = (net.knots_u, net.p, net.knots_v, net.q, net.ctrl, u, v), (net.inv_u, net.inv_v, net.bucket_u,
                                                                         net.bucket_v, out, net.origin)
    run, count = _kernel("scattered_positions" if positions else "scattered", u.size)
    with _on(count):
        if positions:
            run(*head, net.rational, *tail)
        else:
            run(*head, int(order), net.rational, _kernels().binomials(order), *tail)
    return out


def _store(h: np.ndarray, out):
    """``h``, or ``h`` written into ``out`` when given."""
    if out is None:
        return h
    out[...] = h
    return out


def _crowded(net: LocalNet) -> bool:
    """Whether the net's knots are crowded (:func:`surfmod.eval.derivative_nets.crowded`),
    known once per net."""
    known = net.cache.get("crowded")
    if known is None:
        known = net.cache["crowded"] = derivative_nets.crowded(net.knots_u, net.p, net.knots_v, net.q)
    return known


def _from_derivative_nets(net: LocalNet, order: int, positions) -> np.ndarray:
    """Partials ``(..., K, K, 3)`` of ``net`` from its derivative nets
    (:mod:`surfmod.eval.derivative_nets`), each evaluated as positions by
    ``positions(LocalNet) -> (..., 3)``; the nets are built once per net and order.

    A polynomial net's derivative nets are the differences of its own poles (a
    difference of neighbouring poles is exact, and the centring of :func:`prepare`
    would round them first); its positions are the net's own.  A rational net's are the
    differences of the homogeneous net about its centre, the weights apart, and the
    quotient rule puts them together."""
    key = ("derivative_nets", order)
    nets = net.cache.get(key)
    if nets is None:
        nets = net.cache[key] = _derivative_local_nets(net, order)
    kk = order + 1
    if not net.rational:
        first = positions(net)
        h = np.zeros(first.shape[:-1] + (kk, kk, 3))
        h[..., 0, 0, :] = first
        for (k, l), (xyz, _) in nets.items():
            h[..., k, l, :] = positions(xyz)
        return h
    h = None
    for (k, l), (xyz, w) in nets.items():
        a = positions(xyz)
        if h is None:
            h = np.zeros(a.shape[:-1] + (kk, kk, 4))
        h[..., k, l, :3] = a
        h[..., k, l, 3] = positions(w)[..., 0]
    out = surface_quotient(h)
    _add_origin(_centred(net), out[..., 0, 0, :])
    return out


def _derivative_local_nets(net: LocalNet, order: int) -> dict:
    """``{(k, l): (xyz, w)}``: each derivative net as polynomial :class:`LocalNet` s, the
    homogeneous coordinates and (rational nets) the weights in a net of their own
    (``w`` None for a polynomial net, whose own positions are ``(0, 0)``)."""
    base = _centred(net) if net.rational else net
    cartesian = net.cache.get("cartesian")
    if cartesian is not None:
        cartesian = cartesian + (np.zeros(3) if base.origin is None else base.origin,)
    nets = derivative_nets.derivative_nets(base.knots_u, base.p, base.knots_v, base.q,
                                           base.ctrl if net.rational else base.ctrl[..., :3], order, cartesian)
    if net.rational:
        nets[0, 0] = (base.knots_u, base.p, base.knots_v, base.q, base.ctrl)
    out = {}
    for kl, (ku, p, kv, q, poles) in nets.items():
        weights = None
        if net.rational:
            weights = np.zeros(poles.shape[:2] + (3,))
            weights[..., 0] = poles[..., 3]
            weights = prepare(ku, p, kv, q, weights)
        out[kl] = (prepare(ku, p, kv, q, np.ascontiguousarray(poles[..., :3])), weights)
    return out


def homogeneous4(ctrl: np.ndarray) -> np.ndarray:
    """The net as ``(n, m, 4)`` float64, C-contiguous: homogeneous points stay, a
    polynomial net gets a unit weight column (the kernels' inner loop is a 4-vector)."""
    if ctrl.shape[-1] == 4:
        return np.require(ctrl, float, ["C", "W"])
    out = np.ones(ctrl.shape[:-1] + (4,))
    out[..., :3] = ctrl
    return out


_workspace = threading.local()


def _scratch(count: int, per_slot: int) -> np.ndarray:
    """``(slots, per_slot)`` scratch for the grid's rings, one slot per thread that may
    run (numba's thread ids when ``count > 1``), kept per calling thread and reused: a
    fresh ring per call would be paged in each time."""
    slots = 1 if count == 1 else numba_threads()
    buf = getattr(_workspace, "rows", None)
    if buf is None or buf.size < slots * per_slot:
        buf = _workspace.rows = np.empty(slots * per_slot)
    return buf[: slots * per_slot].reshape(slots, per_slot)


def _row_stage_plan(net: LocalNet, sv, bv, rows: int):
    """The vector loops of the grid's row stage (:mod:`surfmod.eval.row_stage`) for
    v-points with spans ``sv`` and basis ``bv`` when ``rows`` net rows are contracted:
    ``(bplan, planes, run_starts, run_kinds)``.

    Vector loops need runs of v-points in consecutive spans (a net with about as many
    spans as points) and the net as coordinate planes, built once per surface, and only
    when the stage reads a quarter of the net or more (a few rows of a big net are not
    worth a copy of all of it).  Otherwise every v-point goes one at a time
    (:func:`_scalar_plan`)."""
    from . import row_stage

    n = net.ctrl.shape[0]
    if rows >= max(64, n // 4):
        starts, kinds = row_stage.runs(sv)
        if np.any(kinds == row_stage.NEXT_SPAN):
            planes = net.cache.get("planes")
            if planes is None:
                planes = net.cache["planes"] = row_stage.net_planes(net.ctrl)
            return np.ascontiguousarray(bv.transpose(1, 2, 0)), planes, starts, kinds
    return _scalar_plan(net, sv, bv)


def _scalar_plan(net: LocalNet, sv, bv):
    """The row stage's plan without vector loops: every v-point one at a time (one
    :data:`~surfmod.eval.row_stage.SCALAR` run), empty planes."""
    from . import row_stage

    return (np.empty((bv.shape[1], bv.shape[2], 0)), np.empty((net.ctrl.shape[0], 4, 0)),
            np.array([0, sv.size]), np.array([row_stage.SCALAR]))


def surface_grid(net: LocalNet, us, vs, order: int, out=None) -> np.ndarray:
    """Cartesian mixed partials on the grid ``us x vs``: ``(len(us), len(vs), K, K, 3)``.

    Everything is written point-major (C order), into ``out`` when given: ``(len(us),
    len(vs), 3)`` for positions (``order == 0``), ``(len(us), len(vs), K, K, 3)`` for
    partials.  Small grids (under :data:`COMPILED_GRID` partials) are evaluated in NumPy
    (:mod:`surfmod.eval.tensor_grid`), the others by its compiled twin
    (:mod:`surfmod.eval.tensor_grid_compiled`: each net row the u-points need is contracted with
    the v-basis once per chunk of v-points into a ring, then each u-point combines its
    rows), the u-points in ascending order (unsorted ones are sorted, and their rows
    put back in place).
    """
    us, vs = writable(us), writable(vs)
    kk = order + 1
    shape = (us.size, vs.size, kk, kk, 3)
    if order > 0 and _crowded(net):
        h = _from_derivative_nets(net, order, lambda d: surface_grid(d, us, vs, 0)[:, :, 0, 0])
        return _store(h, None if out is None else out.reshape(shape))
    net = _centred(net)
    knots_u, p, knots_v, q, ctrl, rational = net[:6]
    if us.size * vs.size * (order + 1) ** 2 < COMPILED_GRID:
        h = tensor_grid(knots_u, p, knots_v, q, ctrl, rational, us, vs, order)
        _add_origin(net, h[:, :, 0, 0])
        if out is None:
            return h
        out[...] = h[:, :, 0, 0] if order == 0 else h
        return out.reshape(shape)
    if out is None:
        out = np.empty((us.size, vs.size, 3) if order == 0 else shape)
    if bool(np.all(us[1:] >= us[:-1])):  # the compiled grid adds the origin itself, while in cache
        _grid_sorted(net, us, vs, order, out.reshape(shape))
    else:  # sorted for the ring, the rows put back in place
        rank = np.argsort(us, kind="stable")
        in_order = np.empty(shape)
        _grid_sorted(net, us[rank], vs, order, in_order)
        out.reshape(shape)[rank] = in_order
    return out.reshape(shape)


def _grid_sorted(net: LocalNet, us, vs, order: int, out) -> None:
    """:func:`surface_grid` through the compiled grid, ``us`` ascending, ``out`` the
    point-major ``(n_u, n_v, K, K, 3)``."""
    k = _kernels()
    knots_u, p, knots_v, q, ctrl, rational = net[:6]
    n, m = ctrl.shape[:2]
    kk, dim = order + 1, 4 if rational else 3
    su, bu = basis_at(knots_u, p, n, us, order)
    sv, bv = basis_at(knots_v, q, m, vs, order)
    first = (su - p).astype(np.int64)
    needed = np.unique(first[:, None] + np.arange(p + 1)).size
    plan = _row_stage_plan(net, sv, bv, needed)
    ring_rows = max(RING_ROWS, p + 1)
    chunk = min(vs.size, CHUNK, max(16, RING_DOUBLES // (ring_rows * kk * dim)))
    run, count = _kernel("tensor_grid", us.size * vs.size)
    scratch = _scratch(count, ring_rows * kk * dim * chunk)
    origin = np.zeros(3) if net.origin is None else net.origin  # added in the kernel, while in cache
    head = (bv, plan[0], sv, q, ctrl, plan[1], dim, bu, p, rational, k.binomials(order), out, origin)
    tail = (ring_rows, chunk, first, plan[2], plan[3])
    if count == 1:
        run(*head, scratch[0], *tail)
        return
    # blocks of u-points the threads share: at least BLOCKS_PER_THREAD a thread, of GRID_MIN_BLOCK or more
    step = max(GRID_MIN_BLOCK, -(-us.size // (BLOCKS_PER_THREAD * count)))
    with _on(count):
        run(*head, scratch, *tail, np.r_[np.arange(0, us.size, step), us.size].astype(np.int64))
