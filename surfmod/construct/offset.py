"""Offsets as B-splines (:func:`offset`), with a pre-check that says where they would fail
(:func:`precheck`: folds and creases, raised naming the ``(u, v)`` region), and thickening
(:func:`thicken`).  See :doc:`/guide/analysis` (section "Offsets").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..eval.basis import basis_matrix, knots_inside
from ..nets.bspline import BSplineSurface
from ..sides import SIDES, side_params
from ..surface import Surface, model_size, require_surface
from ..inputs import make_solid
from ..nets.convert import as_bspline_surface
from ..nets.knots import span_samples
from .offset_surface import OffsetSurface
from .ruled import ruled

#: Margin on ``d k < 1``: closer than this the offset's partials nearly vanish.
FOLD_MARGIN = 1e-6


class OffsetApproximation(BSplineSurface):
    """The bicubic B-spline made by :func:`offset`: ``base``, ``distance``, the requested
    ``tolerance`` and ``max_deviation`` (largest distance to the exact offset at the
    check samples, in the same parameters)."""

    base: Surface
    distance: float = 0.0
    tolerance: float = 0.0
    max_deviation: float = 0.0


def _breaks(s: Surface, direction: int) -> np.ndarray:
    """Distinct knots of a B-spline base inside its domain (ends included), else the ends."""
    lo, hi = s.domain[direction]
    inner = knots_inside(s.knots[direction], lo, hi) if isinstance(s, BSplineSurface) else []
    return np.concatenate([[lo], inner, [hi]])


def _region(u, v, mask) -> str:
    return (f"u in [{u[mask].min():.6g}, {u[mask].max():.6g}], "
            f"v in [{v[mask].min():.6g}, {v[mask].max():.6g}]")


def precheck(s: Surface, distance: float, per_span: int = 8, minimum: int = 33) -> None:
    """Raise ``SurfmodError`` where the offset by ``distance`` folds (``d k >= 1``) or
    where the base has a crease (normal jump across a C0 knot line)."""
    us = span_samples(_breaks(s, 0), per_span)
    vs = span_samples(_breaks(s, 1), per_span)
    if us.size < minimum:
        us = np.linspace(*s.domain[0], minimum)
    if vs.size < minimum:
        vs = np.linspace(*s.domain[1], minimum)
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    c = s.curvatures(uu, vv)
    reach = distance * np.maximum(c.k1, c.k2) if distance > 0 else distance * np.minimum(c.k1, c.k2)
    bad = reach >= 1.0 - FOLD_MARGIN
    if np.any(bad):
        k = np.abs(np.where(distance > 0, c.k1, c.k2)[bad]).max()
        raise SurfmodError(
            f"distance: |{distance:g}| reaches the smallest radius of curvature on the concave side "
            f"({1.0 / k:.6g}) where {_region(uu, vv, bad)}: the offset would fold there")
    if isinstance(s, BSplineSurface):
        for direction, name in ((0, "u"), (1, "v")):
            p, k = s.degree[direction], s.knots[direction]
            lo, hi = s.domain[direction]
            values, mult = np.unique(k[(k > lo) & (k < hi)], return_counts=True)
            other = vs if direction == 0 else us
            for t in values[mult >= p]:
                eps = 1e-9 * max(1.0, hi - lo)
                left, right = np.full_like(other, t - eps), np.full_like(other, t + eps)
                args_l = (left, other) if direction == 0 else (other, left)
                args_r = (right, other) if direction == 0 else (other, right)
                cos = np.einsum("ij,ij->i", s.normals(*args_l), s.normals(*args_r))
                if np.any(cos < 1.0 - 1e-10):
                    where = other[cos < 1.0 - 1e-10]
                    o = "v" if direction == 0 else "u"
                    raise SurfmodError(
                        f"s: the surface has a crease along {name} = {t:.6g} ({o} in [{where.min():.6g}, "
                        f"{where.max():.6g}]): the offset is not defined across it; split the surface there")


def _lsq(params, knots, p, data):
    """Least squares along axis 0 of ``data`` for the B-spline space ``(knots, p)``."""
    n = knots.size - p - 1
    b = basis_matrix(knots, p, n, params)[0]
    flat = data.reshape(data.shape[0], -1)
    sol, *_ = np.linalg.lstsq(b, flat, rcond=None)
    return sol.reshape((n,) + data.shape[1:])


def _base_multiplicities(s: Surface, direction: int) -> dict:
    """Knot multiplicity the cubic fit needs at each interior knot of a B-spline base: the
    base is C^(p-m) there, its offset (through the normal, one derivative down)
    C^(p-m-1), which a cubic carries with multiplicity ``4 - p + m`` (at most 3)."""
    if not isinstance(s, BSplineSurface):
        return {}
    p, k = s.degree[direction], s.knots[direction]
    lo, hi = s.domain[direction]
    values, mult = np.unique(k[(k > lo) & (k < hi)], return_counts=True)
    return {float(t): int(min(3, max(1, 4 - p + m))) for t, m in zip(values, mult)}


def _knots(breaks, mults, p=3):
    inner = np.repeat(breaks[1:-1], [mults.get(float(t), 1) for t in breaks[1:-1]])
    return np.concatenate([np.full(p + 1, breaks[0]), inner, np.full(p + 1, breaks[-1])])


def _fit(exact: Surface, bu, bv, mults, per_span: int = 6):
    us, vs = span_samples(bu, per_span), span_samples(bv, per_span)
    grid = exact.grid(us, vs)
    ku, kv = _knots(bu, mults[0]), _knots(bv, mults[1])
    net = _lsq(us, ku, 3, grid)                                   # (nu, len(vs), 3)
    net = _lsq(vs, kv, 3, net.transpose(1, 0, 2)).transpose(1, 0, 2)
    return BSplineSurface._trusted(net, (3, 3), (ku, kv))


def _span_errors(fit: Surface, exact: Surface, bu, bv):
    """Max parametric distance per (u span, v span) at interior check points."""
    t = np.array([0.17, 0.5, 0.83])
    us = (bu[:-1, None] + t * np.diff(bu)[:, None]).ravel()
    vs = (bv[:-1, None] + t * np.diff(bv)[:, None]).ravel()
    err = np.linalg.norm(fit.grid(us, vs) - exact.grid(us, vs), axis=2)
    return err.reshape(bu.size - 1, 3, bv.size - 1, 3).max(axis=(1, 3))


#: spans of a bicubic approximation (each fit is a least-squares solve on a tensor grid
#: of 6 samples a span: 250 x 250 spans took 10 s of one core)
MAX_SPANS = 65_536
#: tolerances below this fraction of the model size are refused by ``offset``: the
#: least-squares fit's own round-off is ~4e-11 of it (a random Bézier patch's offset
#: stalled at 1.2e-9 on a 29 mm model, at 60,000 spans and 15 s)
FIT_FLOOR = 1e-9


def bicubic_approximation(exact: Surface, bu, bv, tol: float, mults=({}, {}), max_rounds: int = 10):
    """``(fit, max_deviation)``: a bicubic B-spline within ``tol`` of ``exact`` in its own
    parameters, starting from the breakpoints ``bu``, ``bv`` (with the interior knot
    multiplicities ``mults``) and halving every span whose midpoint errors exceed ``tol``.
    Refused (``tolerance:``) before a fit of more than ``MAX_SPANS`` spans by the h^4 rate."""
    bu, bv = np.asarray(bu, float), np.asarray(bv, float)
    if bu.size < 3:
        bu = np.linspace(bu[0], bu[-1], 3)
    if bv.size < 3:
        bv = np.linspace(bv[0], bv[-1], 3)
    for _ in range(max_rounds):
        fit = _fit(exact, bu, bv, mults)
        err = _span_errors(fit, exact, bu, bv)
        bad = err > tol
        if not np.any(bad):
            return fit, float(err.max())
        worst = float(err.max())
        # a bicubic's error falls at most 16-fold per halving (h^4): each span needs at least
        # (err / tol)^(1/4) pieces along each direction, known before the larger fit is made
        need = np.ceil((np.maximum(err, tol) / tol) ** 0.25)
        spans = float(need.max(axis=1).sum()) * float(need.max(axis=0).sum())
        if spans > MAX_SPANS:
            raise SurfmodError(f"tolerance: {tol:g} would need at least {spans:,.0f} bicubic spans (error "
                               f"{worst:.3g} with {err.size:,}), above the limit {MAX_SPANS:,}; loosen it")
        bu = np.union1d(bu, 0.5 * (bu[:-1] + bu[1:])[bad.any(axis=1)])
        bv = np.union1d(bv, 0.5 * (bv[:-1] + bv[1:])[bad.any(axis=0)])
    raise SurfmodError(f"tolerance: {tol:g} not reached after {max_rounds} refinements "
                       f"(max error {err.max():.3g}); loosen it or raise max_rounds")


def _nonzero(value, name: str) -> float:
    """One finite, non-zero number (an offset's distance, a slab's thickness)."""
    x = checks.real(value, name)
    if x == 0.0:
        raise SurfmodError(f"{name}: must be non-zero, got {value!r}")
    return x


def offset(s: Surface, distance: float, tolerance: float = 1e-4, *, max_rounds: int = 10) -> OffsetApproximation:
    """A bicubic B-spline within ``tolerance`` of the offset ``S + distance * N`` (``N``
    the unit normal ``Su x Sv``), in the parameters of ``s``.  Raises ``SurfmodError``
    naming the ``(u, v)`` region where the offset would fold or where ``s`` has a crease.

    >>> import surfmod as sm
    >>> o = sm.offset(sm.CylindricalSurface(2.0, u_range=(0, 1.5), v_range=(0, 3)), 0.5, 1e-6)
    >>> o.max_deviation < 1e-6, round(float(np.linalg.norm(o.points(0.7, 1.0)[:2])), 6)
    (True, 2.5)
    """
    s = require_surface(s, "s")
    d = _nonzero(distance, "distance")
    size = model_size(s) + abs(d)
    tol = checks.tolerance(tolerance, "tolerance", size)
    if tol < FIT_FLOOR * size:
        raise SurfmodError(f"tolerance: {tol:g} is below what a bicubic fit can reach ({FIT_FLOOR:g} x the size "
                           f"{size:.3g} of the surface and its offset)")
    max_rounds = checks.count(max_rounds, "max_rounds")
    precheck(s, d)
    exact = OffsetSurface(s, d)
    mults = (_base_multiplicities(s, 0), _base_multiplicities(s, 1))
    fit, err = bicubic_approximation(exact, _breaks(s, 0), _breaks(s, 1), tol, mults, max_rounds)
    out = OffsetApproximation._trusted(fit.control_points, (3, 3), fit.knots)
    out.base, out.distance, out.tolerance, out.max_deviation = s, d, tol, err
    return out


def thicken(s: Surface, thickness: float, tolerance: float = 1e-5, *, symmetric: bool = False):
    """A closed build123d ``Solid`` between ``s`` and its offset by ``thickness`` (along
    the normal; negative goes the other way), or with ``symmetric=True`` between the two
    offsets by ``-thickness/2`` and ``+thickness/2``: the two faces plus ruled walls along
    the four sides, sewn and oriented outwards (:func:`surfmod.make_solid`).  Sides that
    collapse to a point or close on themselves get no wall.

    >>> import surfmod as sm
    >>> slab = sm.thicken(sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)), 0.5)
    >>> round(slab.volume, 9)
    3.0
    """
    s = require_surface(s, "s")
    t = _nonzero(thickness, "thickness")
    try:
        far = offset(s, t / 2 if symmetric else t, tolerance)
        inner = offset(s, -t / 2, tolerance) if symmetric else None
    except SurfmodError as exc:
        raise SurfmodError(str(exc).replace("distance:", "thickness:", 1)) from None
    near = inner if symmetric else as_bspline_surface(s, "s")
    faces = [near if symmetric else s, far]
    probe = np.linspace(0.0, 1.0, 7)
    for side in SIDES:
        fixed, end = SIDES[side]
        lo, hi = s.domain[1 - fixed]
        pts = s.points(*side_params(s, side, lo + probe * (hi - lo)))
        opposite = s.points(*side_params(s, side[0] + ("1" if end == 0 else "0"), lo + probe * (hi - lo)))
        size = np.ptp(pts, axis=0).max()
        if size < 1e-9 or np.allclose(pts, opposite, atol=1e-9 * max(1.0, size)):
            continue  # a pole, or a closed direction: the faces meet themselves there
        c_near = near.isocurve(**{"uv"[fixed]: near.domain[fixed][end]})
        c_far = far.isocurve(**{"uv"[fixed]: far.domain[fixed][end]})
        faces.append(ruled(c_near, c_far))
    return make_solid(faces)
