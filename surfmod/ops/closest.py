"""Closest points on a surface for many points at once: the closest-point family.

:func:`closest_points` answers in closed form on the elementary surfaces
(:mod:`surfmod.construct.elementary_closest`) and searches every other surface here: seeds
from a sampled grid (:func:`grid_seeds`), then projected Newton in the parameter box on all
starts together (:func:`newton_closest`).  :func:`project_distances` is the family's
distance bound from parameter guesses (the meshers' deviation judge).  Each of
:func:`grid_seeds`, :func:`newton_in_boxes` and :func:`project_distances` has its compiled
twin in :mod:`surfmod.eval.projection_kernel`.  See :doc:`/guide/surfaces` (section
"Closest points").
"""

from __future__ import annotations

import numpy as np

from ..eval.local import COMPILED_SCATTERED
from ..surface import Surface

#: point-cell pairs from which the seeds are searched by the compiled branch and bound
#: (:func:`~surfmod.eval.projection_kernel.grid_seeds_compiled`); fewer, by every triangle
#: in NumPy (:func:`grid_seeds`), cost less than loading the kernel (design_eval.md,
#: "The compiled grid")
COMPILED_SEED_PAIRS = 1 << 21
#: Newton starts from which B-spline projections iterate in the compiled loop; below it
#: NumPy's iteration, whose partials to order 2 (9 a start) then stay below
#: eval.local.COMPILED_SCATTERED and so in NumPy too
COMPILED_NEWTON_STARTS = COMPILED_SCATTERED // 9


def seed_parameters(s: Surface, direction: int, per_span: int = 4, minimum: int = 24, maximum: int = 96) -> np.ndarray:
    """Sample parameters along one direction: ``minimum`` equal steps over the domain
    (so long spans are not starved when short spans hold most knots), every knot, and
    ``per_span`` samples inside each knot span while that stays under ``maximum``."""
    lo, hi = s.domain[direction]
    even = np.linspace(lo, hi, minimum + 1)
    knots = getattr(s, "knots", None)
    if knots is None:
        return even
    k = np.asarray(knots[direction])
    k = np.unique(np.concatenate([[lo, hi], k[(k > lo) & (k < hi)]]))
    if (len(k) - 1) * per_span > maximum:
        return np.unique(np.concatenate([np.linspace(lo, hi, maximum + 1), k]))
    fine = [np.linspace(a, b, per_span, endpoint=False) for a, b in zip(k[:-1], k[1:])]
    return np.unique(np.concatenate(fine + [even, k]))


def nearest_samples(points: np.ndarray, samples: np.ndarray, count: int, chunk: int = 2_000_000) -> np.ndarray:
    """Indices ``(N, count)`` of the ``count`` nearest ``samples`` to each point (chunked)."""
    count = min(count, len(samples))
    out = np.empty((len(points), count), dtype=int)
    step = max(1, chunk // max(1, len(samples)))
    s2 = np.einsum("ij,ij->i", samples, samples)
    for a in range(0, len(points), step):  # loop over memory chunks, not points
        p = points[a : a + step]
        d2 = s2[None, :] - 2 * p @ samples.T
        idx = np.argpartition(d2, count - 1, axis=1)[:, :count] if count < len(samples) else np.argsort(d2, axis=1)
        out[a : a + step] = idx
    return out


def crease_breaks(s: Surface, direction: int) -> np.ndarray:
    """Domain ends and the C0 knot lines (multiplicity >= degree) between them.

    Across such a crease the distance has a kink that Newton cannot settle on, so each
    start works in its own smooth piece between two breaks; a minimum on the crease then
    becomes a constrained (boundary) minimum of the piece.
    """
    lo, hi = s.domain[direction]
    knots, degree = getattr(s, "knots", None), getattr(s, "degree", None)
    if knots is None or degree is None:
        return np.array([lo, hi])
    values, mult = np.unique(np.asarray(knots[direction]), return_counts=True)
    creases = values[(mult >= degree[direction]) & (values > lo) & (values < hi)]
    return np.concatenate([[lo], creases, [hi]])


def _piece_of(breaks: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, len(breaks) - 2)


def newton_closest(s: Surface, points: np.ndarray, u: np.ndarray, v: np.ndarray, iterations: int = 60):
    """Projected Newton on ``|S - P|^2 / 2`` from starts ``(u, v)`` (flat arrays, one per
    point row of ``points``), each kept inside its smooth piece (:func:`crease_breaks`).

    A start that stops on a crease while the distance still falls across it carries on
    in the neighbouring piece, so a minimum beyond a crease is reached and a minimum on
    a crease is one from both sides.  Returns refined ``(u, v)``.
    """
    u, v = u.astype(float).copy(), v.astype(float).copy()
    breaks_u, breaks_v = crease_breaks(s, 0), crease_breaks(s, 1)
    piece_u, piece_v = _piece_of(breaks_u, u), _piece_of(breaks_v, v)
    todo = np.arange(u.size)
    for _ in range(len(breaks_u) + len(breaks_v)):  # each crossing moves one piece on
        pu, pv = piece_u[todo], piece_v[todo]
        box = (breaks_u[pu], breaks_u[pu + 1], breaks_v[pv], breaks_v[pv + 1])
        u[todo], v[todo] = _in_boxes(s, points[todo], u[todo], v[todo], box, iterations)
        d = s._derivatives(u[todo], v[todo], 1)
        r = d[:, 0, 0] - points[todo]
        gu, gv = np.einsum("ij,ij->i", r, d[:, 1, 0]), np.einsum("ij,ij->i", r, d[:, 0, 1])
        # descent leaves the piece through an interior crease: step into the next piece
        down_u = (u[todo] <= box[0]) & (gu > 0) & (piece_u[todo] > 0)
        up_u = (u[todo] >= box[1]) & (gu < 0) & (piece_u[todo] < len(breaks_u) - 2)
        down_v = (v[todo] <= box[2]) & (gv > 0) & (piece_v[todo] > 0)
        up_v = (v[todo] >= box[3]) & (gv < 0) & (piece_v[todo] < len(breaks_v) - 2)
        piece_u[todo] += up_u.astype(int) - down_u.astype(int)
        piece_v[todo] += up_v.astype(int) - down_v.astype(int)
        todo = todo[down_u | up_u | down_v | up_v]
        if todo.size == 0:
            break
    return u, v


def _in_boxes(s: Surface, points, u, v, box, iterations: int):
    """:func:`newton_in_boxes`, compiled for B-spline / NURBS nets with many starts."""
    if not (hasattr(s, "_local_net") and u.size >= COMPILED_NEWTON_STARTS):
        return newton_in_boxes(s, points, u, v, box, iterations)
    from ..eval.kernels import binomials
    from ..eval.projection_kernel import newton_in_boxes_compiled  # numba, loaded on the first large projection

    (du0, du1), (dv0, dv1) = s.domain
    net = s._local_net()
    u, v = np.require(u, float, ["C", "W"]).copy(), np.require(v, float, ["C", "W"]).copy()
    bounds = [np.require(b, float, ["C", "W"]) for b in box]
    newton_in_boxes_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, net.rational, net.inv_u, net.inv_v,
                             net.bucket_u, net.bucket_v, binomials(2), binomials(0),
                             np.require(points, float, ["C", "W"]), u, v, *bounds, float(du1 - du0), float(dv1 - dv0),
                             int(iterations))
    return u, v


def newton_in_boxes(s: Surface, points, u, v, box, iterations: int):
    """The projected Newton iteration, each start ``(u, v)`` confined to its box
    ``(u0, u1, v0, v1)`` (arrays); returns the refined ``(u, v)`` (new arrays)."""
    (du0, du1), (dv0, dv1) = s.domain
    spanu, spanv = du1 - du0, dv1 - dv0
    u, v = u.copy(), v.copy()
    active = np.ones(u.shape, bool)
    for _ in range(iterations):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        uu, vv, pp = u[idx], v[idx], points[idx]
        u0, u1, v0, v1 = (bound[idx] for bound in box)
        d = s._derivatives(uu, vv, 2)
        S, Su, Sv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1]
        r = S - pp
        gu, gv = np.einsum("ij,ij->i", r, Su), np.einsum("ij,ij->i", r, Sv)
        a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((Su, Su), (Su, Sv), (Sv, Sv)))
        huu = a + np.einsum("ij,ij->i", r, d[:, 2, 0])
        huv = b + np.einsum("ij,ij->i", r, d[:, 1, 1])
        hvv = c + np.einsum("ij,ij->i", r, d[:, 0, 2])
        tiny = 1e-300 + 1e-14 * (a + c) ** 2
        # held at a bound, the step is one-dimensional: its own second derivative decides
        # (the 2x2 Hessian may be indefinite through the other direction)
        huu_1d = np.maximum(np.where(huu > 1e-14 * (a + c), huu, a), 1e-300)
        hvv_1d = np.maximum(np.where(hvv > 1e-14 * (a + c), hvv, c), 1e-300)
        indefinite = (huu <= 0) | (hvv <= 0) | (huu * hvv - huv**2 <= tiny)
        huu, huv, hvv = np.where(indefinite, a, huu), np.where(indefinite, b, huv), np.where(indefinite, c, hvv)
        huu = np.maximum(huu, 1e-300 + 1e-14 * (a + c))
        hvv = np.maximum(hvv, 1e-300 + 1e-14 * (a + c))
        det = np.maximum(huu * hvv - huv**2, tiny)
        du = (-gu * hvv + gv * huv) / det
        dv = (-gv * huu + gu * huv) / det
        # constrained step: a parameter held at its bound when the descent leaves the domain
        fix_u = ((uu <= u0) & (gu > 0)) | ((uu >= u1) & (gu < 0))
        fix_v = ((vv <= v0) & (gv > 0)) | ((vv >= v1) & (gv < 0))
        du = np.where(fix_u, 0.0, np.where(fix_v, -gu / huu_1d, du))
        dv = np.where(fix_v, 0.0, np.where(fix_u, -gv / hvv_1d, dv))
        # no jumps across the whole patch in one step
        du = np.clip(du, -0.25 * spanu, 0.25 * spanu)
        dv = np.clip(dv, -0.25 * spanv, 0.25 * spanv)
        f0 = np.einsum("ij,ij->i", r, r)
        nu, nv = np.clip(uu + du, u0, u1), np.clip(vv + dv, v0, v1)
        trial = np.arange(idx.size)
        step = 1.0
        for _ in range(8):  # backtracking on the points whose distance grew
            rn = s._derivatives(nu[trial], nv[trial], 0)[:, 0, 0] - pp[trial]
            worse = np.einsum("ij,ij->i", rn, rn) > f0[trial] * (1 + 1e-12) + 1e-300
            trial = trial[worse]
            if trial.size == 0:
                break
            step /= 4
            nu[trial] = np.clip(uu[trial] + step * du[trial], u0[trial], u1[trial])
            nv[trial] = np.clip(vv[trial] + step * dv[trial], v0[trial], v1[trial])
        # no decrease even for a tiny step: converged to round-off, stay
        nu[trial], nv[trial] = uu[trial], vv[trial]
        moved = np.maximum(np.abs(nu - uu) / spanu, np.abs(nv - vv) / spanv)
        u[idx], v[idx] = nu, nv
        # quadratic convergence: a step below 1e-10 leaves an error ~1e-20
        active[idx] = moved > 1e-10
    return u, v


def _even_chords(t: np.ndarray, chords: np.ndarray) -> np.ndarray:
    """As many parameters as ``t`` whose steps have equal cumulative chord length."""
    arc = np.concatenate([[0.0], np.cumsum(chords)])
    if not arc[-1] > 0:
        return t
    return np.interp(np.linspace(0.0, arc[-1], len(t)), arc, t)


def seed_grid(s: Surface):
    """Seed parameters ``(us, vs)`` and their grid points.

    The knot-based samples of :func:`seed_parameters` are moved to equal steps of chord
    length (the longest chord across the other direction) and the knots added back, so
    that stretched regions -- strongly varying weights, long spans -- are sampled as
    finely in space as the rest; otherwise a coarse triangle there may hide the closest
    point.
    """
    us, vs = seed_parameters(s, 0), seed_parameters(s, 1)
    g = s.grid(us, vs)
    chords_u = np.linalg.norm(np.diff(g, axis=0), axis=-1).max(axis=1)
    chords_v = np.linalg.norm(np.diff(g, axis=1), axis=-1).max(axis=0)
    us = np.unique(np.concatenate([_even_chords(us, chords_u), _knots_inside(s, 0)]))
    vs = np.unique(np.concatenate([_even_chords(vs, chords_v), _knots_inside(s, 1)]))
    return us, vs, s.grid(us, vs)


def _knots_inside(s: Surface, direction: int) -> np.ndarray:
    knots = getattr(s, "knots", None)
    if knots is None:
        return np.empty(0)
    lo, hi = s.domain[direction]
    k = np.asarray(knots[direction])
    return k[(k >= lo) & (k <= hi)]


#: triangle-point pairs per block: the block's temporaries stay a few MiB
BLOCK_PAIRS = 1 << 17


def triangle_tables(g: np.ndarray):
    """Per-cell data of the grid ``g (nu, nv, 3)``: corners, edges and the 2x2 Gram
    matrices of the two triangles ``(i,j),(i+1,j),(i+1,j+1)`` and ``(i,j),(i+1,j+1),(i,j+1)``,
    and the cell diameters.  Arrays are ``(nu-1, nv-1, ...)``."""
    p00, p10, p11, p01 = g[:-1, :-1], g[1:, :-1], g[1:, 1:], g[:-1, 1:]
    e = np.stack([p10 - p00, p11 - p00, p11 - p00, p01 - p00], axis=2)  # (.., 4, 3): e0,e1 of tri 0, of tri 1
    gram = np.einsum("...ad,...ad->...a", e[..., [0, 1, 2, 3], :], e[..., [0, 1, 2, 3], :])
    cross = np.stack([np.einsum("...d,...d->...", e[..., 0, :], e[..., 1, :]),
                      np.einsum("...d,...d->...", e[..., 2, :], e[..., 3, :])], axis=-1)
    corners = (p00, p10, p11, p01)
    diam2 = np.zeros(p00.shape[:2])
    for a in range(4):
        for b in range(a + 1, 4):
            diff = corners[a] - corners[b]
            diam2 = np.maximum(diam2, np.einsum("...d,...d->...", diff, diff))
    return (np.ascontiguousarray(e), np.ascontiguousarray(gram), np.ascontiguousarray(cross),
            np.sqrt(diam2))


def row_diameters(diam: np.ndarray) -> np.ndarray:
    """The largest cell diameter of each row of cells (prunes whole rows at once)."""
    return np.ascontiguousarray(diam.max(axis=1))


def _unit_quotient(num, det):
    """``clip(num / det, 0, 1)`` for ``det > 0``, forming only the quotients inside
    ``(0, 1)``: a degenerate triangle (a pole's collapsed edge, ``det`` at its 1e-300
    floor) seen from a far point (1e60) would otherwise overflow to inf before the clip.

    >>> _unit_quotient(np.array([-1.0, 0.5, 1e60]), np.array([1.0, 1.0, 1e-300])).tolist()
    [0.0, 0.5, 1.0]
    """
    inside = (num > 0.0) & (num < det)
    q = np.divide(num, det, out=np.zeros(np.broadcast_shapes(np.shape(num), np.shape(det))), where=inside)
    return np.where(num >= det, 1.0, q)


def _feet(a, e0, e1, d00, d11, d01):
    """Squared distances and clipped barycentric ``(beta, gamma)`` of the feet of the
    points ``a`` (relative to each triangle's first corner, ``(B, C, 3)``) on the triangles
    spanned by ``e0``, ``e1``; the operations of the compiled twin's ``_foot``."""
    r0 = a[..., 0] * e0[:, 0] + a[..., 1] * e0[:, 1] + a[..., 2] * e0[:, 2]
    r1 = a[..., 0] * e1[:, 0] + a[..., 1] * e1[:, 1] + a[..., 2] * e1[:, 2]
    det = np.maximum(d00 * d11 - d01 * d01, 1e-300)
    beta = _unit_quotient(d11 * r0 - d01 * r1, det)
    gamma = _unit_quotient(d00 * r1 - d01 * r0, det)
    over = np.maximum(beta + gamma, 1.0)
    beta, gamma = beta / over, gamma / over
    f = [beta * e0[:, d] + gamma * e1[:, d] - a[..., d] for d in range(3)]
    return f[0] * f[0] + f[1] * f[1] + f[2] * f[2], beta, gamma


def _bottoms(d2):
    """Samples no farther than any of their eight neighbours: ``(B, nu, nv)`` bools."""
    padded = np.pad(d2, ((0, 0), (1, 1), (1, 1)), constant_values=np.inf)
    nu, nv = d2.shape[1:]
    ok = np.ones(d2.shape, bool)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            if di != 1 or dj != 1:
                ok &= ~(padded[:, di : di + nu, dj : dj + nv] < d2)
    return ok


def _smallest(x, k: int) -> np.ndarray:
    """Per row the indices of the ``k`` smallest entries, in rising order (ties by index,
    as the kernel's insertion keeps them): a partition, then a sort of ``k`` entries."""
    if k < x.shape[1]:
        pick = np.argpartition(x, k - 1, axis=1)[:, :k]
    else:
        pick = np.broadcast_to(np.arange(x.shape[1]), x.shape).copy()
    vals = np.take_along_axis(x, pick, axis=1)
    order = np.lexsort((pick, vals), axis=1)
    return np.take_along_axis(pick, order, axis=1)


def grid_seeds(points, us, vs, g, e, gram, cross, seeds: int, n_basins: int) -> np.ndarray:
    """Starts ``(N, seeds + n_basins, 2)`` in (u, v) (tables of :func:`triangle_tables`):
    the ``seeds`` triangles with the nearest clipped feet (ties in the order of cells),
    entered at those feet, then the ``n_basins`` deepest bottoms of the sampled distance
    (samples no farther than their eight neighbours); short lists repeat their first.
    Every triangle for every point, where the compiled twin prunes by branch and bound.

    >>> us = vs = np.linspace(0, 1, 3)
    >>> g = np.stack([*np.meshgrid(us, vs, indexing="ij"), np.zeros((3, 3))], axis=-1)
    >>> e, gram, cross, _ = triangle_tables(g)
    >>> grid_seeds(np.array([[0.3, 0.6, 1.0]]), us, vs, g, e, gram, cross, 1, 1)[0].round(12).tolist()
    [[0.3, 0.6], [0.5, 0.5]]
    """
    nu, nv = g.shape[:2]
    cells = (nu - 1) * (nv - 1)
    corner = g[:-1, :-1].reshape(cells, 3)
    edges, grams, crosses = e.reshape(cells, 4, 3), gram.reshape(cells, 4), cross.reshape(cells, 2)
    ci, cj = np.divmod(np.arange(cells), nv - 1)
    out = np.empty((len(points), seeds + n_basins, 2))
    take = min(seeds, 2 * cells)
    step = max(1, BLOCK_PAIRS // (2 * cells))
    for a0 in range(0, len(points), step):  # loop over memory blocks, not points
        pts = points[a0 : a0 + step]
        rel = pts[:, None, :] - corner[None]  # (B, C, 3)
        d = np.empty((len(pts), cells, 2))
        bg = np.empty((len(pts), cells, 2, 2))
        for t in range(2):
            d[..., t], bg[..., t, 0], bg[..., t, 1] = _feet(rel, edges[:, 2 * t], edges[:, 2 * t + 1], grams[:, 2 * t],
                                                             grams[:, 2 * t + 1], crosses[:, t])
        key = _smallest(d.reshape(len(pts), -1), take)  # key = 2 cell + t
        cell, t = np.divmod(key, 2)
        beta = bg.reshape(len(pts), -1, 2)[np.arange(len(pts))[:, None], key, 0]
        gamma = bg.reshape(len(pts), -1, 2)[np.arange(len(pts))[:, None], key, 1]
        i, j = ci[cell], cj[cell]
        w0 = 1.0 - beta - gamma
        first = t == 0  # corners (i,j), (i+1,j), (i+1,j+1); else (i,j), (i+1,j+1), (i,j+1)
        u = np.where(first, w0 * us[i] + beta * us[i + 1] + gamma * us[i + 1],
                     w0 * us[i] + beta * us[i + 1] + gamma * us[i])
        v = np.where(first, w0 * vs[j] + beta * vs[j] + gamma * vs[j + 1],
                     w0 * vs[j] + beta * vs[j + 1] + gamma * vs[j + 1])
        block = out[a0 : a0 + step]
        block[:, :take, 0], block[:, :take, 1] = u, v
        block[:, take:seeds] = block[:, :1]
        # valley bottoms of the sampled distance, deepest first (ties in raster order)
        diff = g[None] - pts[:, None, None, :]
        d2 = diff[..., 0] * diff[..., 0] + diff[..., 1] * diff[..., 1] + diff[..., 2] * diff[..., 2]
        flat = np.where(_bottoms(d2), d2, np.inf).reshape(len(pts), -1)
        order = _smallest(flat, min(n_basins, flat.shape[1]))
        found = np.take_along_axis(flat, order, axis=1) < np.inf
        nearest = np.argmin(d2.reshape(len(pts), -1), axis=1)
        order[:, 0] = np.where(found[:, 0], order[:, 0], nearest)  # none (NaN): the nearest sample
        found[:, 0] = True
        order = np.where(found, order, order[:, :1])
        bi, bj = np.divmod(order, nv)
        block[:, seeds:, 0], block[:, seeds:, 1] = us[bi], vs[bj]
    return out


def seed_starts(points, us, vs, g, seeds: int) -> np.ndarray:
    """Newton starts ``(N, seeds + max(2, seeds // 2), 2)`` in (u, v) for each point: the
    starts of :func:`grid_seeds`, whose valley bottoms are there because in a nearly flat
    valley all nearest triangles sit in one basin.  Large work runs in the compiled
    branch and bound (``grid_seeds_compiled``: cells whose nearest corner is farther
    than the current ``seeds``-th foot plus the cell's diameter are skipped)."""
    e, gram, cross, diam = triangle_tables(g)
    n_basins = max(2, seeds // 2)
    if len(points) * diam.size < COMPILED_SEED_PAIRS:  # small work: NumPy, no numba to load
        return grid_seeds(points, us, vs, g, e, gram, cross, int(seeds), int(n_basins))
    from ..eval.projection_kernel import grid_seeds_compiled  # numba, loaded on the first large projection

    out = np.empty((len(points), seeds + n_basins, 2))
    grid_seeds_compiled(np.require(points, float, ["C", "W"]), np.require(g, float, ["C", "W"]),
                        np.require(us, float, ["C", "W"]), np.require(vs, float, ["C", "W"]),
                        e, gram, cross, diam, row_diameters(diam), int(seeds), int(n_basins), out)
    return out


def project_distances(d1, points, uv, bounds, iterations: int = 6, threshold: float = 0.0, d0=None) -> np.ndarray:
    """Distance from ``points`` (N, 3) to a surface, by Gauss-Newton from the parameter
    guesses ``uv`` (N, 2), clipped to ``bounds = (u0, u1, v0, v1)``.

    ``d1(u, v)`` returns ``(N, >=2, >=2, 3)`` derivatives (``d0`` optionally positions
    only).  Every iterate is a point of the surface, so the smallest distance seen is an
    upper bound of the true distance (for the guarantee, over-estimating is the safe
    side).  Points whose bound is ``<= threshold`` (at first or after an iteration) are
    not iterated further: below the threshold the bound is all that is asked.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> d = project_distances(lambda u, v: s._derivatives(u, v, 1),
    ...     np.array([[0.2, 0.7, 0.5]]), np.array([[0.0, 0.0]]), (0, 1, 0, 1))
    >>> float(d[0])
    0.5
    """
    u0, u1, v0, v1 = bounds
    u = np.clip(uv[:, 0], u0, u1)
    v = np.clip(uv[:, 1], v0, v1)
    first = d0(u, v) if d0 is not None else d1(u, v)[:, 0, 0]
    best = np.linalg.norm(points - first, axis=1)
    act = np.nonzero(best > threshold)[0]
    step_u, step_v = 0.25 * (u1 - u0), 0.25 * (v1 - v0)
    ua, va = u[act], v[act]
    for _ in range(iterations):
        if act.size == 0:
            break
        ders = d1(ua, va)
        r = points[act] - ders[:, 0, 0]
        best[act] = np.minimum(best[act], np.linalg.norm(r, axis=1))
        su, sv = ders[:, 1, 0], ders[:, 0, 1]
        # the Gram matrix of (Su, Sv, r) per point in one product: a, b, c and the gradient
        gram = np.matmul(np.stack([su, sv, r], axis=1), np.stack([su, sv], axis=2))
        a, b, c, g1, g2 = gram[:, 0, 0], gram[:, 0, 1], gram[:, 1, 1], gram[:, 2, 0], gram[:, 2, 1]
        det = a * c - b * b
        det = det + 1e-14 * (a + c) ** 2 + np.finfo(float).tiny
        du = np.clip((c * g1 - b * g2) / det, -step_u, step_u)
        dv = np.clip((a * g2 - b * g1) / det, -step_v, step_v)
        un = np.clip(ua + du, u0, u1)
        vn = np.clip(va + dv, v0, v1)
        # Gauss-Newton is quadratic near the foot point: once the 3-D step is below 1e-3 of
        # the distance, the distance is known to ~1e-6 relative and the point is done
        step3 = np.linalg.norm((un - ua)[:, None] * su + (vn - va)[:, None] * sv, axis=1)
        moving = (step3 > 1e-3 * best[act]) & (best[act] > threshold)
        # converged points already have their distance in ``best``
        act, ua, va = act[moving], un[moving], vn[moving]
    if act.size:
        last = d0(ua, va) if d0 is not None else d1(ua, va)[:, 0, 0]
        best[act] = np.minimum(best[act], np.linalg.norm(points[act] - last, axis=1))
    return best


def closest_points(s: Surface, points: np.ndarray, seeds: int = 8):
    """``(u, v, point, distance)`` flat arrays for ``(N, 3)`` points (trusted input).

    >>> import surfmod as sm
    >>> u, v, p, d = closest_points(sm.plane((0, 0, 0), (2, 0, 0), (0, 1, 0)), np.array([[1.0, 0.5, 3.0]]))
    >>> u, v, d
    (array([0.5]), array([0.5]), array([3.]))
    """
    closed_form = s._closest_parameters(points)
    if closed_form is not None:  # planes, cylinders, cones, spheres, tori: no search
        u, v = closed_form
        pts = s._derivatives(u, v, 0)[:, 0, 0]
        return u, v, pts, np.linalg.norm(pts - points, axis=1)
    us, vs, g = seed_grid(s)
    start = seed_starts(points, us, vs, g, seeds)
    k = start.shape[1]
    rep = np.repeat(points, k, axis=0)
    # about half the starts of a point repeat another one exactly (a valley bottom at a
    # triangle's corner, short lists padded): iterate each distinct start once
    owner = np.repeat(np.arange(len(points)), k)
    flat = start.reshape(-1, 2)
    _, first, inverse = np.unique(np.c_[owner, flat], axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    u, v = newton_closest(s, rep[first], flat[first, 0], flat[first, 1])
    u, v = u[inverse], v[inverse]
    pts = s._derivatives(u, v, 0)[:, 0, 0]
    dist = np.linalg.norm(pts - rep, axis=1).reshape(-1, k)
    best = np.argmin(dist, axis=1)
    pick = np.arange(len(points)) * k + best
    return u[pick], v[pick], pts[pick], dist[np.arange(len(points)), best]
