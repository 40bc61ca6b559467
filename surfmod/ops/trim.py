"""Trimming a surface by closed boundary loops in its (u, v) parameter space.

``trim`` builds the trimmed build123d ``Face`` in OCCT (p-curve wires on the surface);
``trimmed_area`` is the independent NumPy side: the area ``∬ |Su x Sv| du dv`` over the
trimmed region by Green's theorem, ``∬_R f = ∮_∂R F dv`` with
``F(u, v) = ∫_{u0}^{u} f(s, v) ds``, both integrals by Gauss-Legendre quadrature split at
the knot lines of the surface, so the integrand is smooth on every piece.
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import checks
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve
from ..nets.knots import span_samples
from .clip import as_face_surface
from ..readback.trimmed import TrimmedFace
from ..surface import Surface, model_size, require_surface

#: OCCT's ``Precision::Confusion()``: the smallest distance its topology tells apart
OCCT_CONFUSION = 1e-7

#: Closing gap allowed between the first and last point of a loop, relative to the domain.
CLOSURE_RTOL = 1e-9


class Loop:
    """One closed parameter-space loop: a polyline ``(N, 2)`` or a 2-D B-spline curve."""

    def __init__(self, kind, data):
        self.kind, self.data = kind, data

    def polygon(self, per_span: int = 16) -> np.ndarray:
        """Closed polygon approximating the loop (exact for polylines)."""
        if self.kind == "polyline":
            return self.data
        curve = self.data
        t = _curve_breaks(curve, per_span)
        return curve.points(t)[:, :2]

    def signed_area(self) -> float:
        p = self.polygon(64)
        return 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))

    def reversed(self) -> "Loop":
        if self.kind == "polyline":
            return Loop("polyline", self.data[::-1].copy())
        c = self.data
        k = c.knots
        return Loop("bspline", BSplineCurve._trusted(c.control_points[::-1], c.degree, (k[0] + k[-1]) - k[::-1], None if c.weights is None else c.weights[::-1]))

    def occ_spec(self):
        if self.kind == "polyline":
            return ("polyline", self.data)
        c = self.data
        return ("bspline", c.control_points[:, :2], c.degree, c.knots, c.weights)


def _curve_breaks(curve, per_span):
    return span_samples(np.unique(curve.knots[curve.degree : len(curve.control_points) + 1]), per_span)


def _loop(value, name, domain) -> Loop:
    (u0, u1), (v0, v1) = domain
    size = max(u1 - u0, v1 - v0)
    if isinstance(value, Curve):
        curve = value.to_bspline()
        if curve.control_points.shape[1] != 3 or np.any(np.abs(curve.control_points[:, 2]) > 1e-12 * size):
            raise SurfmodError(f"{name}: a (u, v) curve must lie in the z = 0 plane (x = u, y = v)")
        ends = curve.points(np.array(curve.domain))[:, :2]
        if np.linalg.norm(ends[0] - ends[1]) > CLOSURE_RTOL * size:
            raise SurfmodError(f"{name}: the loop is not closed (end is {np.linalg.norm(ends[0] - ends[1]):.3g} from start)")
        loop = Loop("bspline", curve)
        pts = loop.polygon(32)
    else:
        pts = checks.finite_array(value, name, ndim=2, last=2)
        if len(pts) < 4:
            raise SurfmodError(f"{name}: a closed polyline needs at least 4 points (3 corners + the closing point), got {len(pts)}")
        gap = float(np.linalg.norm(pts[0] - pts[-1]))
        if gap > CLOSURE_RTOL * size:
            raise SurfmodError(f"{name}: the loop is not closed (last point is {gap:.3g} from the first; repeat the first point at the end)")
        pts = pts.copy()
        pts[-1] = pts[0]
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        if np.any(seg <= 1e-14 * size):
            raise SurfmodError(f"{name}: repeated consecutive points (zero-length segment {int(np.argmin(seg))})")
        loop = Loop("polyline", checks.frozen(pts))
    slack = 1e-9 * size
    if pts[:, 0].min() < u0 - slack or pts[:, 0].max() > u1 + slack or pts[:, 1].min() < v0 - slack or pts[:, 1].max() > v1 + slack:
        raise SurfmodError(f"{name}: the loop leaves the parameter domain [{u0:g}, {u1:g}] x [{v0:g}, {v1:g}]")
    if abs(loop.signed_area()) <= 1e-14 * size * size:
        raise SurfmodError(f"{name}: the loop encloses no area")
    return loop


def boundary_loops(s: Surface, boundary_curve_uv) -> list[Loop]:
    """Validated loops, oriented: the outer one counter-clockwise, holes clockwise."""
    if isinstance(boundary_curve_uv, (Curve, np.ndarray)) or _is_point_list(boundary_curve_uv):
        raw = [boundary_curve_uv]
    else:
        try:
            raw = list(boundary_curve_uv)
        except TypeError:
            raise SurfmodError(
                f"boundary_curve_uv: expected an (N, 2) closed polyline, a 2-D curve or a list of loops, got {type(boundary_curve_uv).__name__}"
            ) from None
    if not raw:
        raise SurfmodError("boundary_curve_uv: no loop given")
    name = "boundary_curve_uv" if len(raw) == 1 else "boundary_curve_uv[{}]"
    loops = [_loop(r, name.format(i), s.domain) for i, r in enumerate(raw)]
    out = []
    for i, loop in enumerate(loops):
        ccw = loop.signed_area() > 0
        out.append(loop if ccw == (i == 0) else loop.reversed())
    return out


def _is_point_list(value) -> bool:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return arr.ndim == 2


def trim(s: Surface, boundary_curve_uv, *, tolerance: float = 1e-7):
    """A build123d ``Face`` on ``s`` bounded by closed loops in its (u, v) parameter space.

    ``boundary_curve_uv`` is one closed polyline ``(N, 2)`` (last point = first point), a
    2-D curve (a surfmod curve in the z = 0 plane, x = u, y = v, e.g. a closed
    ``BSplineCurve``), or a list of such loops: the first is the outer boundary, the rest
    are holes.  Orientation is fixed automatically.  The face is built in OCCT with
    ``BRepBuilderAPI_MakeFace`` on wires of p-curves, 3-D edges from
    ``BRepLib.BuildCurves3d_s``.

    >>> import numpy as np, surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0))
    >>> square = [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75), (0.25, 0.25)]
    >>> round(sm.trim(s, square).area, 9)
    1.0
    """
    s = require_surface(s, "s")
    tol = checks.tolerance(tolerance, "tolerance", model_size(s))
    # the 3-D edges are approximated from the p-curves to this tolerance (BRepLib
    # BuildCurves3d): below OCCT's confusion tolerance it only multiplies segments (1e-11
    # on a unit square took 22 s) and OCCT's own checks cannot tell the difference
    if tol < OCCT_CONFUSION:
        raise SurfmodError(f"tolerance: {tol:g} is below OCCT's confusion tolerance {OCCT_CONFUSION:g} "
                           "(Precision::Confusion), the finest edge OCCT builds")
    loops = boundary_loops(s, boundary_curve_uv)
    from ..occ.faces import trimmed_face

    return trimmed_face(s.geom(), [loop.occ_spec() for loop in loops], tol)


def _surface_breaks(s: Surface, direction: int, fallback: int = 4) -> np.ndarray:
    lo, hi = s.domain[direction]
    knots = getattr(s, "knots", None)
    if knots is not None:
        k = np.asarray(knots[direction])
        k = k[(k >= lo) & (k <= hi)]
        return np.unique(np.concatenate([[lo, hi], k]))
    return np.linspace(lo, hi, fallback + 1)


def _area_density(s: Surface, u, v):
    d = s._derivatives(u, v, 1)
    return np.linalg.norm(np.cross(d[:, 1, 0], d[:, 0, 1]), axis=-1)


def _inner_integral(s: Surface, u, v, ubreaks, order):
    """``F(u, v) = ∫_{u0}^{u} |Su x Sv|(s, v) ds`` for flat arrays, split at ``ubreaks``."""
    x, w = np.polynomial.legendre.leggauss(order)
    a = ubreaks[:-1][None, :]
    b = np.minimum(ubreaks[1:][None, :], u[:, None])
    length = np.clip(b - a, 0.0, None)  # (P, K)
    nodes = a[..., None] + (x + 1)[None, None, :] / 2 * length[..., None]  # (P, K, G)
    vv = np.broadcast_to(v[:, None, None], nodes.shape)
    f = _area_density(s, nodes.ravel(), vv.ravel()).reshape(nodes.shape)
    return np.einsum("pkg,g,pk->p", f, w, length / 2)


def _polyline_pieces(p, ubreaks, vbreaks):
    """Split the segments of a closed polyline at every knot line they cross:
    arrays of piece end points ``(M, 2)``, ``(M, 2)``."""
    a, b = p[:-1], p[1:]
    ts = [np.zeros(len(a)), np.ones(len(a))]
    for axis, breaks in ((0, ubreaks), (1, vbreaks)):
        d = b[:, axis] - a[:, axis]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (breaks[None, :] - a[:, axis, None]) / d[:, None]
        t = np.where((t > 0) & (t < 1), t, np.nan)
        ts.append(t.T)
    allt = np.sort(np.vstack([np.atleast_2d(t) for t in ts]).T, axis=1)  # (S, J) with NaN last
    t0, t1 = allt[:, :-1], allt[:, 1:]
    keep = np.isfinite(t0) & np.isfinite(t1) & (t1 > t0)
    seg = np.nonzero(keep)[0]
    t0, t1 = t0[keep], t1[keep]
    return a[seg] + t0[:, None] * (b[seg] - a[seg]), a[seg] + t1[:, None] * (b[seg] - a[seg])


def _curve_crossings(curve, ubreaks, vbreaks, per_span: int = 8, dense: int = 64) -> np.ndarray:
    """Parameters splitting a (u, v) curve into pieces on which the area integrand is smooth:
    its own knots (each span cut ``per_span`` times) plus every crossing of a knot line
    of the surface (bracketed on a dense sample, refined by vectorized bisection)."""
    base = _curve_breaks(curve, per_span)
    t = _curve_breaks(curve, dense)
    uv = curve.points(t)[:, :2]
    lo, hi, axis, level = [], [], [], []
    for ax, breaks in ((0, ubreaks), (1, vbreaks)):
        g = uv[:, ax, None] - breaks[None, :]  # (T, K)
        i, k = np.nonzero(g[:-1] * g[1:] < 0)
        lo.append(t[i]), hi.append(t[i + 1]), axis.append(np.full(i.size, ax)), level.append(breaks[k])
    lo, hi, axis, level = (np.concatenate(a) for a in (lo, hi, axis, level))
    if lo.size:
        sign_lo = np.sign(curve.points(lo)[np.arange(lo.size), axis] - level)
        for _ in range(60):
            mid = (lo + hi) / 2
            g = curve.points(mid)[np.arange(mid.size), axis] - level
            same = np.sign(g) == sign_lo
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        base = np.concatenate([base, (lo + hi) / 2])
    return np.unique(base)


def trimmed_area(s: Surface, boundary_curve_uv=None, order: int = 24) -> float:
    """Area of the trimmed region, by NumPy quadrature (Green's theorem in (u, v)).

    It is the NumPy side of :func:`trim` (same arguments), checked against the face it
    builds.  Without ``boundary_curve_uv``, ``s`` is a face and its own boundary is used:
    deprecated, that is ``sm.from_face(face).area()``.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0))
    >>> round(trimmed_area(s, [(0, 0), (0.5, 0), (0, 0.5), (0, 0)]), 12)
    0.5
    """
    if boundary_curve_uv is None:
        face = as_face_surface(s)
        if not isinstance(face, TrimmedFace):
            raise SurfmodError("boundary_curve_uv: needed unless s is a face (it carries its own boundary)")
        # deprecated (one release): a face's area has one name, sm.from_face(face).area()
        warnings.warn("trimmed_area(face) is deprecated: use sm.from_face(face).area()", DeprecationWarning, stacklevel=2)
        return face.area()
    s = require_surface(s, "s")
    order = checks.count(order, "order", minimum=2)
    loops = boundary_loops(s, boundary_curve_uv)
    ub, vb = _surface_breaks(s, 0), _surface_breaks(s, 1)
    x, w = np.polynomial.legendre.leggauss(order)
    total = 0.0
    for loop in loops:
        if loop.kind == "polyline":
            a, b = _polyline_pieces(loop.data, ub, vb)
            pts = a[:, None, :] + (x + 1)[None, :, None] / 2 * (b - a)[:, None, :]
            dv = (b - a)[:, 1] / 2  # dv/dx of the affine piece
            uv = pts.reshape(-1, 2)
            F = _inner_integral(s, uv[:, 0], uv[:, 1], ub, order).reshape(pts.shape[:2])
            total += float(np.einsum("mg,g,m->", F, w, dv))
        else:
            curve = loop.data
            t = _curve_crossings(curve, ub, vb)
            t0, t1 = t[:-1], t[1:]
            tt = (t0[:, None] + (x + 1)[None, :] / 2 * (t1 - t0)[:, None]).ravel()
            d = curve._derivatives(tt, 1)
            F = _inner_integral(s, d[:, 0, 0], d[:, 0, 1], ub, order)
            total += float(np.sum((F * d[:, 1, 1]).reshape(-1, order) * w[None, :] * ((t1 - t0) / 2)[:, None]))
    return total
