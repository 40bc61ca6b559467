"""Cross-checking a surfmod object against its OCCT twin.

``parametric`` mode (the construct is exact in OCCT): positions, first and second
derivatives, normals and curvatures from the NumPy evaluator are compared with OCCT's
``D2`` and ``GeomLProp_SLProps`` at the same parameters, on a grid that contains the
domain ends, every knot and any seam.

``geometric`` mode (OCCT only approximates the construct: sweeps, lofts, fits): the
distance from every NumPy point to the OCCT face is measured.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import checks, tolerances
from .construct.elementary import ElementarySurface
from .errors import SurfmodError
from .curve import Curve
from .eval.differential import curvatures, degenerate_mask, unit_normals
from .nets import mp_reference
from .nets.knots import smooth_mask, span_samples
from .readback import from_face
from .readback.trimmed import TrimmedFace
from .surface import Surface, model_size


class _CrossCheckFields(NamedTuple):
    max_deviation: float
    mode: str
    samples: int
    passed: bool


class CrossCheck(_CrossCheckFields):
    """Result of :func:`crosscheck`: ``(max_deviation, mode, samples, passed)``.

    ``max_deviation`` is the largest position deviation in model units; ``details``
    (an attribute, not a field) holds the per-quantity figures.

    >>> import surfmod as sm
    >>> r = sm.crosscheck(sm.sphere(2.0), samples=9)
    >>> r.mode, r.passed, r.max_deviation < 1e-12, "normal" in r.details
    ('parametric', True, True, True)
    """

    details: dict

    def __repr__(self):
        state = "passed" if self.passed else "FAILED"
        return f"CrossCheck({self.mode}, {self.samples} samples, max deviation {self.max_deviation:.3g}, {state})"


def _result(max_dev, mode, samples, passed, details):
    out = CrossCheck(float(max_dev), mode, int(samples), bool(passed))
    out.details = details
    return out


def sample_parameters(lo: float, hi: float, count: int, extra=()) -> np.ndarray:
    """``count`` equally spaced values plus the given extra values (knots, seams), sorted."""
    base = np.linspace(lo, hi, count)
    extra = np.asarray([x for x in extra if lo <= x <= hi], dtype=float)
    return np.unique(np.concatenate([base, extra]))


def _knots_in(obj, direction):
    knots = getattr(obj, "knots", None)
    if knots is None:
        return ()
    return knots[direction] if isinstance(knots, tuple) else knots


def _smooth(s, direction, t, order):
    """False where the ``order``-th derivative jumps across a knot at ``t``.  A face on a
    periodic B-spline trimmed across its seam lives in a shifted period: its parameters
    are wrapped into the knots' period first (wrapped, a shifted knot lands within an ulp
    of the knot, on either side, while OCCT snaps it onto the knot)."""
    knots = getattr(s, "knots", None)
    if knots is None:
        return np.ones(t.shape, dtype=bool)
    if isinstance(s, TrimmedFace):
        t = s._wrap(np.asarray(t, dtype=float), direction)
    return smooth_mask(knots[direction], s.degree[direction], t, order)


def _short_span_points(s, uu, vv) -> np.ndarray:
    """True at parameters on knot spans shorter than ``SHORT_SPAN_RTOL`` of the domain
    (ends included).  Files from other systems carry spans ~1e-11 wide (e.g. knots
    ``[-2.9e-11]*4 + [0, 0.059, ...]``): a derivative there is a difference of control
    points over ``h^k`` and the curvature is meaningless in any evaluator, OCCT's too."""
    knots = getattr(s, "knots", None)
    out = np.zeros(uu.shape, dtype=bool)
    if not isinstance(knots, tuple):
        return out
    for direction, t in ((0, uu), (1, vv)):
        lo, hi = s.domain[direction]
        k = np.unique(np.asarray(knots[direction], dtype=float))
        a, b = k[:-1], k[1:]
        short = (b - a) < tolerances.SHORT_SPAN_RTOL * max(hi - lo, 1e-300)
        for x0, x1 in zip(a[short], b[short]):
            out |= (t >= x0) & (t <= x1)
    return out


SAMPLINGS = ("dense", "sufficient")


def crosscheck(obj, samples: int = 64, tolerance: float | None = None, *, sampling: str = "dense") -> CrossCheck:
    """Compare ``obj`` with OCCT; works on surfmod surfaces and curves, and on build123d /
    OCP faces (read back with :func:`surfmod.from_face`).

    ``sampling="dense"`` compares a ``samples`` x ``samples`` grid plus every knot;
    ``sampling="sufficient"`` (what ``surfmod check`` uses) compares, per direction, the
    smaller of that grid and a set on which agreement with OCCT implies agreement
    everywhere on the face (see :func:`sufficient_parameters`).

    >>> import surfmod as sm
    >>> r = sm.crosscheck(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), samples=8)
    >>> r.mode, r.passed, r.samples
    ('parametric', True, 64)
    >>> sm.crosscheck(sm.CylindricalSurface(2.0, v_range=(0, 5)), samples=24, sampling="sufficient").samples
    25
    """
    result = crosscheck_many([obj], samples, sampling=sampling, tolerance=tolerance)[0]
    if isinstance(result, SurfmodError):
        raise result
    return result


#: parameter values per direction on an elementary surface: 5 values over the face's
#: range give at least 4 distinct angles mod 2 pi (see :func:`sufficient_parameters`)
ELEMENTARY_SAMPLES = 5


def sufficient_parameters(s, direction: int, samples: int) -> np.ndarray:
    """Parameters of one direction at which agreement with OCCT is enough to conclude
    agreement over the whole face: the smaller of the dense set (``samples`` values plus
    every knot) and

    * on planes, cylinders, cones, spheres and tori, ``min(samples, 5)`` equally spaced
      values.  Both evaluators are ``sum_k c_k phi_k(u, v)`` over a fixed tensor basis
      (``{1, u} x {1, v}`` for planes; ``{1, cos u, sin u} x {1, v}`` for cylinders and
      cones; ``{1, cos u, sin u} x {1, cos v, sin v}`` for spheres and tori) with
      coefficients from the frame and radii, and so are their derivatives; a tensor grid
      with three distinct angles mod 2 pi (or two distinct linear values) per direction is
      unisolvent for these spaces, so equal values there mean equal functions.
    * on B-spline and Bezier directions, ``p + 2`` values per knot span (span ends shared;
      ``2p + 2`` if rational).  On a span both evaluators are polynomials of degree ``p``
      (``N / w`` with ``N``, ``w`` of degree ``p`` if rational, and the difference of two
      such quotients has a numerator of degree ``2p``): ``p + 1`` (``2p + 1``) values fix
      them, and the ``p`` (``2p``) interior values alone fix the first and second
      derivatives (degree ``p - 1``) where they jump at the knots.  Parameters a
      tolerance beyond the knot range continue the end span and belong to it; a periodic
      direction trimmed across its seam has the knots shifted by the period.

    >>> import surfmod as sm
    >>> sufficient_parameters(sm.PlaneSurface((0, 0, 0), (0, 0, 1), u_range=(0, 1), v_range=(0, 1)), 0, 24).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    >>> s = sm.BSplineSurface(np.random.default_rng(0).uniform(size=(4, 4, 3)), (3, 3))
    >>> sufficient_parameters(s, 0, 24).tolist()   # one bicubic span: 5 values
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    lo, hi = s.domain[direction]
    surface = s.surface if isinstance(s, TrimmedFace) else s
    if isinstance(surface, ElementarySurface) and samples > ELEMENTARY_SAMPLES and hi > lo:
        return np.linspace(lo, hi, ELEMENTARY_SAMPLES)  # no knots: the dense set is larger
    dense = sample_parameters(lo, hi, samples, _knots_in(s, direction))
    knots = getattr(surface, "knots", None)
    if not isinstance(knots, tuple) or hi <= lo:
        return dense
    p = int(surface.degree[direction])
    per_span = 2 * p + 2 if getattr(surface, "weights", None) is not None else p + 2
    breaks = np.unique(np.asarray(knots[direction], dtype=float))
    period = s.periods[direction] if isinstance(s, TrimmedFace) else None
    if period:
        breaks = np.concatenate([breaks + k * period for k in (-2, -1, 0, 1, 2)])
    else:
        breaks = breaks[1:-1]  # beyond the end knots the end spans continue
    inner = breaks[(breaks > lo) & (breaks < hi)]
    ends = np.unique(np.concatenate([[lo], inner, [hi]]))
    if (ends.size - 1) * (per_span - 1) + 1 >= dense.size:
        return dense
    return span_samples(ends, per_span - 1)


def crosscheck_many(objs, samples: int = 64, *, sampling: str = "dense", tolerance: float | None = None) -> list:
    """:func:`crosscheck` of many surfaces or faces at once: per object a
    :class:`CrossCheck` (the same figures as ``crosscheck`` gives it alone) or the
    :class:`~surfmod.errors.SurfmodError` that reading or sampling it raised.  OCCT is
    sampled face by face; the comparison runs once over all samples, so the fixed NumPy
    cost is paid once rather than per face (what ``surfmod check`` needs on parts of
    thousands of faces).

    >>> import surfmod as sm, build123d as bd
    >>> [r.passed for r in crosscheck_many(bd.Box(1, 2, 3).faces()[:2], 8)]
    [True, True]
    """
    samples = checks.count(samples, "samples", minimum=2)
    if tolerance is not None:
        tolerance = checks.positive(tolerance, "tolerance")
    if sampling not in SAMPLINGS:
        raise SurfmodError(f"sampling: expected one of {', '.join(SAMPLINGS)}, got {sampling!r}")
    out: list = [None] * len(objs)
    batch, where = [], []
    for i, obj in enumerate(objs):
        try:
            if isinstance(obj, Curve):
                out[i] = _check_curve(obj, samples)
                continue
            if not isinstance(obj, Surface):
                obj = from_face(obj)
            # a pass threshold below round-off of the surface's size could never pass
            limit = None if tolerance is None else checks.tolerance(tolerance, "tolerance", model_size(obj))
            if not obj.exact_in_occt:
                out[i] = _check_geometric(obj, samples, limit)
                continue
            batch.append(_parametric_samples(obj, samples, sampling == "sufficient"))
            where.append(i)
        except SurfmodError as exc:
            out[i] = exc
        if len(batch) == BATCH_FACES:
            for j, result in zip(where, _judge_parametric(batch)):
                out[j] = result
            batch, where = [], []
    for j, result in zip(where, _judge_parametric(batch)):
        out[j] = result
    return out


#: faces compared in one vectorized pass: enough to pay NumPy's fixed costs once per
#: many faces, few enough to bound the memory of a part with thousands of faces
BATCH_FACES = 256


_DERIVATIVES = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2))


def _own_differentials(s) -> bool:
    """True if ``s`` computes normals or curvatures its own way (then the check calls
    them); otherwise they are :mod:`surfmod.eval.differential` of its derivatives, which
    the check computes for all faces at once (the same numbers at regular points)."""
    cls = type(s)
    return not (cls.normals is Surface.normals and cls.curvatures is Surface.curvatures
                and cls._regular_derivatives is Surface._regular_derivatives and cls._evaluate is Surface._evaluate)


def _parametric_samples(s: Surface, samples: int, sufficient: bool) -> dict:
    """Everything the parametric comparison needs from one surface: both sides' samples
    (OCCT's ``Value``/``D2`` and ``GeomLProp``), masks and per-face scales."""
    from .occ.sample import surface_props, surface_values_d2

    (u0, u1), (v0, v1) = s.domain
    if sufficient:
        us, vs = sufficient_parameters(s, 0, samples), sufficient_parameters(s, 1, samples)
    else:
        us = sample_parameters(u0, u1, samples, _knots_in(s, 0))
        vs = sample_parameters(v0, v1, samples, _knots_in(s, 1))
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    mine = s._derivatives(uu, vv, 2)
    geom = s.geom()
    occ = surface_values_d2(geom, uu, vv)  # positions from Value: exact even where D2 loses digits
    # at knots where a derivative jumps it is two-valued (each evaluator takes one side):
    # compare it only where smooth, and the normal (curvature) only where the first (second)
    # derivatives are single-valued; the samples so skipped are counted in the report
    jump_n = jump_k = np.zeros(uu.shape, dtype=bool)
    if getattr(s, "knots", None) is not None:
        for k, l in _DERIVATIVES:
            jump = ~(_smooth(s, 0, uu, k) & _smooth(s, 1, vv, l))
            occ[jump, k, l] = mine[jump, k, l]
        jump_n = ~(_smooth(s, 0, uu, 1) & _smooth(s, 1, vv, 1))
        jump_k = ~(_smooth(s, 0, uu, 2) & _smooth(s, 1, vv, 2))
    # on knot spans a round-off wide, only positions are meaningful (see _short_span_points)
    short = _short_span_points(s, uu, vv)
    if short.any():
        for k, l in _DERIVATIVES:
            occ[short, k, l] = mine[short, k, l]
    pos_scale = max(float(np.abs(mine[:, 0, 0]).max()), 1.0)
    sub = np.arange(0, uu.size, max(1, uu.size // 1024))  # GeomLProp is slow; a dense subset
    n_occ, k_occ = surface_props(geom, uu[sub], vv[sub])
    own = None
    if _own_differentials(s):
        c = s.curvatures(uu[sub], vv[sub])
        own = (s.normals(uu[sub], vv[sub]), np.stack([c.gaussian, c.mean, c.k1, c.k2], axis=1))
    return {
        "mine": mine, "occ": occ, "short": short, "sub": sub, "n_occ": n_occ, "k_occ": k_occ, "own": own,
        "jump_n": jump_n[sub], "jump_k": jump_k[sub], "jump_points": int(jump_k.sum()),
        "surface": s, "uv_sub": (uu[sub], vv[sub]),
        "d_tol": tolerances.occt_derivative_rtol(max(getattr(s, "degree", (0, 0)))),
        # short knot spans amplify round-off in derivatives on both sides (differences of
        # control points over span lengths): never demand more than that round-off allows
        "roundoff": _roundoff_scales(s, pos_scale),
        "span": max(u1 - u0, v1 - v0),
    }


def _segment_max(values, starts, mask=None, empty=0.0, ignore_nan=False):
    """Per segment (starting at ``starts``) the largest value where ``mask`` holds,
    ``empty`` where it holds nowhere; NaN wins unless ``ignore_nan`` (then as ``nanmax``)."""
    if mask is not None:
        values = np.where(mask, values, -np.inf)
    out = (np.fmax if ignore_nan else np.maximum).reduceat(values, starts)
    return np.where(out == -np.inf, empty, out)


def _judge_parametric(faces: list) -> list:
    """Compare the gathered samples of many faces in one vectorized pass (per-face maxima
    by segment) and judge each face against its limits."""
    if not faces:
        return []
    sizes = np.array([len(f["mine"]) for f in faces])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    seg = np.repeat(np.arange(len(faces)), sizes)
    mine = np.concatenate([f["mine"] for f in faces])
    occ = np.concatenate([f["occ"] for f in faces])
    short = np.concatenate([f["short"] for f in faces])
    d_tol = np.array([f["d_tol"] for f in faces])
    r1, r2 = np.array([f["roundoff"] for f in faces]).T
    span = np.array([f["span"] for f in faces])
    i1, j1 = [1, 0], [0, 1]
    i2, j2 = [2, 1, 0], [0, 1, 2]
    n = len(mine)

    pos_scale = np.maximum(_segment_max(np.abs(mine[:, 0, 0]).max(axis=1), starts), 1.0)
    d1_scale = np.maximum(_segment_max(np.abs(mine[:, i1, j1]).reshape(n, -1).max(axis=1), starts, ~short), 1e-300)
    # a (near-)zero second derivative (bilinear patches, planes) is judged against the first
    # derivative over the domain size, not against its own round-off
    d2_max = _segment_max(np.abs(mine[:, i2, j2]).reshape(n, -1).max(axis=1), starts, ~short)
    d2_scale = np.maximum(np.maximum(d2_max, d1_scale / span), 1e-300)
    d1_scale, d2_scale = np.maximum(d1_scale, r1 / d_tol), np.maximum(d2_scale, r2 / d_tol)
    pos_dev = _segment_max(np.abs(mine[:, 0, 0] - occ[:, 0, 0]).max(axis=1), starts)
    d1_dev = np.fmax.reduce(np.abs(mine[:, i1, j1] - occ[:, i1, j1]).reshape(n, -1), axis=1)
    d2_dev = np.fmax.reduce(np.abs(mine[:, i2, j2] - occ[:, i2, j2]).reshape(n, -1), axis=1)
    d1_rel = _segment_max(d1_dev, starts, ignore_nan=True) / d1_scale
    d2_rel = _segment_max(d2_dev, starts, ignore_nan=True) / d2_scale

    # normals and curvature where both sides call them defined (off degenerate points)
    sub_sizes = np.array([len(f["sub"]) for f in faces])
    sub_starts = np.concatenate([[0], np.cumsum(sub_sizes)[:-1]])
    sub = np.concatenate([f["sub"] + s0 for f, s0 in zip(faces, starts)])
    sub_seg = seg[sub]
    ders = mine[sub]
    n_occ = np.concatenate([f["n_occ"] for f in faces])
    k_occ = np.concatenate([f["k_occ"] for f in faces])
    with np.errstate(all="ignore"):  # degenerate points are computed, then left out
        n_mine = unit_normals(ders)
        c = curvatures(ders)
        k_mine = np.stack([c.gaussian, c.mean, c.k1, c.k2], axis=1)
        for f, s0, size in zip(faces, sub_starts, sub_sizes):
            if f["own"] is not None:
                n_mine[s0 : s0 + size], k_mine[s0 : s0 + size] = f["own"]
        # at degenerate points (poles, collapsed edges) OCCT's CSLib normal ignores the side
        # the limit is taken from and may be reversed; surfmod's is the limit from inside
        ok = np.all(np.isfinite(n_occ), axis=1) & ~degenerate_mask(ders, tolerances.DEGENERATE_NORMAL) & ~short[sub]
        ok &= ~np.concatenate([f["jump_n"] for f in faces])
        dev, explained = _normal_turns(ders, n_mine, n_occ, d1_scale[sub_seg])
        okk = np.all(np.isfinite(k_occ), axis=1) & ok & ~np.concatenate([f["jump_k"] for f in faces])
        k_scale = np.maximum(_segment_max(np.abs(k_occ).max(axis=1), sub_starts, okk), 1.0 / pos_scale)
        # Gaussian curvature has units 1/L^2: compare it against k_scale^2
        diff = np.abs(k_mine - k_occ)
        ks = k_scale[sub_seg]
        k_point = np.maximum(diff[:, 0] / ks**2, diff[:, 1:].max(axis=1) / ks)
    normal_dev = _segment_max(dev, sub_starts, ok)
    normal_cond = _segment_max(explained, sub_starts, ok)
    k_dev = _segment_max(k_point, sub_starts, okk)
    short_count = np.add.reduceat(short.astype(np.int64), starts)

    out = []
    for i in range(len(faces)):
        details = {
            "position": float(pos_dev[i]),
            "position_rel": float(pos_dev[i] / pos_scale[i]),
            "d1_rel": float(d1_rel[i]),
            "d2_rel": float(d2_rel[i]),
            "normal": float(normal_dev[i]),
            "normal_conditioned": float(normal_cond[i]),
            "curvature_rel": float(k_dev[i]),
            "derivative_tolerance": float(d_tol[i]),
            "short_span_points": int(short_count[i]),
            # samples on knot lines where the surface is only C1 (or C0): the orders it has
            # not got there were skipped, not compared
            "knot_jump_points": faces[i]["jump_points"],
        }
        limits = {
            "position_rel": tolerances.CROSSCHECK_POSITION_RTOL,
            "d1_rel": d_tol[i],
            "d2_rel": d_tol[i],
            "normal_conditioned": max(tolerances.CROSSCHECK_NORMAL_RTOL, d_tol[i]),
            "curvature_rel": max(tolerances.CROSSCHECK_CURVATURE_RTOL, d_tol[i]),
        }
        failed = {k: (details[k], float(lim)) for k, lim in limits.items() if not details[k] <= lim}
        if "curvature_rel" in failed:
            s0, size = sub_starts[i], sub_sizes[i]
            verdict = _settle_curvature(faces[i], k_mine[s0 : s0 + size], k_occ[s0 : s0 + size],
                                        np.where(okk[s0 : s0 + size], k_point[s0 : s0 + size], -np.inf),
                                        float(k_scale[i]), limits["curvature_rel"])
            if verdict is not None:
                details["curvature_settled"] = verdict
                if verdict.startswith("surfmod right"):
                    del failed["curvature_rel"]
        details["failed"] = failed
        out.append(_result(pos_dev[i], "parametric", sizes[i], not failed, details))
    return out


#: samples of a face whose curvature disagreement the high-precision evaluation settles
SETTLE_POINTS = 3


def _settle_curvature(face: dict, k_mine, k_occ, k_point, k_scale: float, limit: float) -> str | None:
    """Who is right where surfmod's and OCCT's curvatures disagree: the worst
    ``SETTLE_POINTS`` samples evaluated from the net in 40-digit arithmetic
    (:mod:`surfmod.nets.mp_reference`, no code shared with either evaluator).  A line
    ``"surfmod right: ..."`` or ``"surfmod wrong: ..."`` with both errors, or ``None`` for a
    surface that is no B-spline net."""
    s = face["surface"]
    base = s.surface if isinstance(s, TrimmedFace) else s
    if getattr(base, "control_points", None) is None or not isinstance(getattr(base, "knots", None), tuple):
        return None
    uu, vv = face["uv_sub"]
    if isinstance(s, TrimmedFace):  # the net's own period
        uu, vv = s._wrap(uu, 0), s._wrap(vv, 1)
    worst = np.argsort(k_point)[::-1][:SETTLE_POINTS]
    worst = worst[np.isfinite(k_point[worst])]
    if worst.size == 0:
        return None
    err_mine = err_occ = 0.0
    scale = np.array([k_scale**2, k_scale, k_scale, k_scale])  # the Gaussian is 1/L^2
    for j in worst:
        ref = np.array(mp_reference.mp_curvatures(base.control_points, getattr(base, "weights", None), base.degree,
                                               base.knots, float(uu[j]), float(vv[j])))
        err_mine = max(err_mine, float((np.abs(k_mine[j] - ref) / scale).max()))
        err_occ = max(err_occ, float((np.abs(k_occ[j] - ref) / scale).max()))
    side = "surfmod right" if err_mine <= limit else "surfmod wrong"
    return (f"{side}: at the {worst.size} worst samples the 40-digit curvature (mpmath on the net) is "
            f"{err_mine:.1e} from surfmod's and {err_occ:.1e} from OCCT's")


def _roundoff_scales(s, pos_scale: float) -> tuple[float, float]:
    """Round-off sizes of first and second derivatives of a spline, ``eps`` times the
    condition ``|P| p!/(p-k)! / h^k`` (``h`` the shortest non-empty knot span), times 100.

    A derivative is a sum of control points weighted by basis derivatives that cancel
    (they sum to zero) and grow like ``h^-k``; any evaluator, OCCT's included, carries an
    absolute error of that order.  Surfaces without knots give zeros.
    """
    knots, degree = getattr(s, "knots", None), getattr(s, "degree", None)
    if knots is None or not isinstance(knots, tuple):
        return 0.0, 0.0
    factors = []
    for kv, p in zip(knots, degree):
        spans = np.diff(np.asarray(kv, dtype=float)[p : len(kv) - p])
        width = max(float(spans.sum()), 1e-300)
        spans = spans[spans >= tolerances.SHORT_SPAN_RTOL * width]  # judged on positions only
        h = float(spans.min()) if spans.size else width
        factors.append((p / h, p * max(p - 1, 0) / h**2))
    (fu1, fu2), (fv1, fv2) = factors
    eps = 100 * np.finfo(float).eps * pos_scale
    return eps * max(fu1, fv1), eps * max(fu2, fv2, fu1 * fv1)


def _normal_turns(ders, n_mine, n_occ, d1_scale) -> tuple[np.ndarray, np.ndarray]:
    """Per point ``(|n_mine - n_occ|_max, the same weighted by the normal's conditioning)``.

    A unit normal from ``Su x Sv`` turns by about ``|dS| |S_max| / |Su x Sv|`` for a
    derivative perturbation ``dS``: near poles and collapsed edges a round-off-sized
    derivative difference turns it visibly.  The conditioned figure converts the turn back
    into the derivative difference that explains it, relative to the derivative scale.
    """
    dev = np.abs(n_mine - n_occ).max(axis=1)
    su = np.linalg.norm(ders[:, 1, 0], axis=1)
    sv = np.linalg.norm(ders[:, 0, 1], axis=1)
    cross = np.linalg.norm(np.cross(ders[:, 1, 0], ders[:, 0, 1]), axis=1)
    return dev, dev * cross / np.maximum(su, sv) / d1_scale


def _check_geometric(s: Surface, samples: int, tolerance: float | None) -> CrossCheck:
    from .occ.sample import distances_to_surface

    tol = tolerance if tolerance is not None else getattr(s, "tolerance", None) or tolerances.GEOMETRIC_TOL
    (u0, u1), (v0, v1) = s.domain
    us = np.linspace(u0, u1, samples)
    vs = np.linspace(v0, v1, samples)
    pts = s.grid(us, vs).reshape(-1, 3)
    geom = s.geom()
    bounds = getattr(s, "occ_bounds", None)
    dist = distances_to_surface(geom, pts, geom.Bounds() if bounds is None else bounds)
    if np.any(np.isnan(dist)):
        from .occ.sample import distances_to_face

        miss = np.isnan(dist)
        dist[miss] = distances_to_face(s.face().wrapped, pts[miss])
    max_dev = float(dist.max())
    return _result(max_dev, "geometric", len(pts), max_dev <= tol, {"tolerance": tol, "mean": float(dist.mean())})


def _check_curve(c: Curve, samples: int) -> CrossCheck:
    from .occ.sample import curve_d2

    t0, t1 = c.domain
    knots = getattr(c, "knots", ())
    t = sample_parameters(t0, t1, samples, knots)
    mine = c._derivatives(t, 2)
    occ = curve_d2(c.geom(), t)
    scale = max(float(np.abs(mine[:, 0]).max()), 1.0)
    pos_dev = float(np.abs(mine[:, 0] - occ[:, 0]).max())
    d_rel = float(np.nanmax(np.abs(mine[:, 1:] - occ[:, 1:])) / max(float(np.abs(mine[:, 1:]).max()), 1e-300))
    passed = pos_dev <= tolerances.EXACT_RTOL * scale * 10 and d_rel <= tolerances.DERIVATIVE_RTOL
    return _result(pos_dev, "parametric", t.size, passed, {"position": pos_dev, "derivatives_rel": d_rel})
