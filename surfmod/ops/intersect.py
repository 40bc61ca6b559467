"""Surface–surface, surface–plane and line–surface intersection on the NumPy evaluator.

Curves are traced by :mod:`surfmod.ops.marching` (predictor along the tangent, Newton
corrector) from seeds found by sampling: for two surfaces, every sample of ``a`` lying
within a grid cell of a sample of ``b`` starts a Newton solve with one parameter of ``a``
held on its grid line, so every intersection curve longer than a grid cell crosses a
grid line and is found; for a plane, sign changes of the signed distance along the grid
lines of the surface.  Line hits are vectorized Newton solves from the samples near the
line.  An empty intersection is an empty result, never an error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..construct.elementary import PlaneSurface
from ..construct.plane import ThreePointPlane
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve
from .clip import as_face_surface, clip_curves
from ..surface import Surface, require_surface
from . import marching
from .closest import closest_points, nearest_samples, seed_parameters
from tqdm import tqdm

# -- problems -------------------------------------------------------------------------------


def seeded_size(*surfaces) -> float:
    pts = np.concatenate([s.grid(seed_parameters(s, 0, 2, 8, 16), seed_parameters(s, 1, 2, 8, 16)).reshape(-1, 3) for s in surfaces])
    return max(float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))), 1e-300)


class IntersectionProblem:
    def __init__(self, domains, scale, tolerance):
        self.lo = np.array([d[0] for d in domains], dtype=float)
        self.hi = np.array([d[1] for d in domains], dtype=float)
        span = self.hi - self.lo
        self.span = np.where(np.isfinite(span), span, scale)
        self.scale = scale
        self.tolerance = tolerance


class SurfaceSurface(IntersectionProblem):
    """Unknowns ``(u, v, s, t)``; ``F = A(u, v) - B(s, t)``."""

    def __init__(self, a, b, tolerance):
        super().__init__([*a.domain, *b.domain], seeded_size(a, b), tolerance)
        self.a, self.b = a, b

    def evaluate(self, X):
        da = self.a._derivatives(X[:, 0], X[:, 1], 1)
        db = self.b._derivatives(X[:, 2], X[:, 3], 1)
        F = da[:, 0, 0] - db[:, 0, 0]
        J = np.stack([da[:, 1, 0], da[:, 0, 1], -db[:, 1, 0], -db[:, 0, 1]], axis=-1)
        zero = np.zeros_like(F)
        dP = np.stack([da[:, 1, 0], da[:, 0, 1], zero, zero], axis=-1)
        return F, J, da[:, 0, 0], dP


class SurfacePlane(IntersectionProblem):
    """Unknowns ``(u, v)``; ``F = n . (A(u, v) - o)`` (signed distance to the plane)."""

    def __init__(self, a, origin, normal, tolerance):
        super().__init__(list(a.domain), seeded_size(a), tolerance)
        self.a, self.origin, self.normal = a, origin, normal

    def evaluate(self, X):
        d = self.a._derivatives(X[:, 0], X[:, 1], 1)
        F = ((d[:, 0, 0] - self.origin) @ self.normal)[:, None]
        J = np.stack([d[:, 1, 0] @ self.normal, d[:, 0, 1] @ self.normal], axis=-1)[:, None, :]
        dP = np.stack([d[:, 1, 0], d[:, 0, 1]], axis=-1)
        return F, J, d[:, 0, 0], dP


class SurfaceLine(IntersectionProblem):
    """Unknowns ``(u, v, w)``; ``F = A(u, v) - (o + w d)``, ``d`` a unit vector."""

    def __init__(self, a, origin, direction, tolerance):
        super().__init__([*a.domain, (-np.inf, np.inf)], seeded_size(a), tolerance)
        self.a, self.origin, self.direction = a, origin, direction

    def evaluate(self, X):
        d = self.a._derivatives(X[:, 0], X[:, 1], 1)
        F = d[:, 0, 0] - (self.origin + X[:, 2:3] * self.direction)
        J = np.stack([d[:, 1, 0], d[:, 0, 1], np.broadcast_to(-self.direction, F.shape)], axis=-1)
        dP = np.stack([d[:, 1, 0], d[:, 0, 1], np.zeros_like(F)], axis=-1)
        return F, J, d[:, 0, 0], dP


# -- results --------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class IntersectionCurve:
    """One traced intersection curve.

    ``points (N, 3)`` on the first surface, ``uv_a (N, 2)`` its parameters there,
    ``uv_b (N, 2)`` the parameters on the second surface (for an infinite plane: the
    coordinates in the plane's frame ``plane_frame``), unit ``tangents (N, 3)`` along the
    polyline, ``closed`` when the curve is a loop (then the last point repeats the
    first).

    >>> import surfmod as sm, numpy as np
    >>> (c,) = sm.intersect(sm.sphere(2.0), ((0, 0, 0), (0, 0, 1)))   # sphere x equator plane
    >>> c.closed, bool(np.allclose(np.linalg.norm(c.points, axis=1), 2.0))
    (True, True)
    """

    points: np.ndarray
    uv_a: np.ndarray
    uv_b: np.ndarray
    tangents: np.ndarray
    closed: bool

    @property
    def length(self) -> float:
        """Arc length of the cubic Hermite curve through the points with their exact
        tangents (error ~h^4, far below the polyline's chordal error)."""
        return hermite_length(self.points, self.tangents)

    def polyline(self):
        """The points as a degree-1 ``BSplineCurve`` (chord-length knots)."""
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(self.points, axis=0), axis=1))])
        chord = chord / chord[-1]
        return BSplineCurve._trusted(self.points, 1, np.concatenate([[0.0], chord, [1.0]]))

    def __len__(self):
        return len(self.points)


def hermite_length(points: np.ndarray, tangents: np.ndarray, order: int = 8) -> float:
    """Length of the C1 cubic Hermite spline through ``points`` with unit ``tangents``
    scaled by each chord."""
    p0, p1 = points[:-1], points[1:]
    c = np.linalg.norm(p1 - p0, axis=1)[:, None]
    m0, m1 = tangents[:-1] * c, tangents[1:] * c
    x, w = np.polynomial.legendre.leggauss(order)
    t = (x + 1) / 2
    # derivative of the Hermite basis
    h00, h10, h01, h11 = 6 * t**2 - 6 * t, 3 * t**2 - 4 * t + 1, -6 * t**2 + 6 * t, 3 * t**2 - 2 * t
    d = (
        h00[None, :, None] * p0[:, None]
        + h10[None, :, None] * m0[:, None]
        + h01[None, :, None] * p1[:, None]
        + h11[None, :, None] * m1[:, None]
    )
    return float(np.sum(np.linalg.norm(d, axis=2) * w[None, :]) / 2)


def _curves(problem, traced, uv_b_of):
    out = []
    for X, closed in traced:
        P = problem.evaluate(X)[2]
        _, t3 = marching.tangent(problem, X)
        t3 = t3 / np.linalg.norm(t3, axis=1, keepdims=True)
        dirs = np.gradient(P, axis=0) if len(P) > 2 else np.repeat(P[1:] - P[:1], len(P), axis=0)
        t3 = t3 * np.sign(np.einsum("ij,ij->i", t3, dirs))[:, None]
        uv_b = uv_b_of(X, P)
        curve = IntersectionCurve(*(checks.frozen(a) for a in (P, X[:, :2], uv_b, t3)), bool(closed))
        out.append(curve)
    return out


# -- seeds ----------------------------------------------------------------------------------


def _grid(s):
    us, vs = seed_parameters(s, 0), seed_parameters(s, 1)
    g = s.grid(us, vs)
    cell = max(np.linalg.norm(np.diff(g, axis=0), axis=2).max(), np.linalg.norm(np.diff(g, axis=1), axis=2).max())
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    return us, vs, uu.ravel(), vv.ravel(), g.reshape(-1, 3), float(cell)


def _surface_surface_seeds(problem):
    a, b = problem.a, problem.b
    _, _, ua, va, pa, ca = _grid(a)
    _, _, ub, vb, pb, cb = _grid(b)
    near = nearest_samples(pa, pb, 1)[:, 0]
    dist = np.linalg.norm(pa - pb[near], axis=1)
    cand = np.nonzero(dist <= ca + cb)[0]
    if cand.size == 0:
        return np.empty((0, 4))
    X = np.stack([ua[cand], va[cand], ub[near[cand]], vb[near[cand]]], axis=1)
    seeds = []
    for j in (0, 1):  # hold u (then v) of the first surface on its grid line
        C = np.zeros_like(X)
        C[:, j] = 1.0
        Xs, _, ok = marching.newton(problem, X, C, X[:, j])
        seeds.append(Xs[ok])
    return np.concatenate(seeds)


def implicit_seeds(problem, s):
    """Zeros of the scalar ``F`` of a 2-unknown problem along the grid lines of ``s``."""
    us, vs, uu, vv, _, _ = _grid(s)
    X = np.stack([uu, vv], axis=1)
    F = problem.evaluate(X)[0][:, 0].reshape(len(us), len(vs))
    starts, fixed = [], []
    # sign changes along u (v held: edges (i, j) - (i + 1, j)), then along v
    for axis, (lo, hi) in enumerate(((F[:-1], F[1:]), (F[:, :-1], F[:, 1:]))):
        i, j = np.nonzero(lo * hi < 0)
        t = lo[i, j] / (lo[i, j] - hi[i, j])
        uv = [us[i], vs[j]]
        lines, k = (us, i) if axis == 0 else (vs, j)
        uv[axis] = lines[k] + t * (lines[k + 1] - lines[k])
        starts.append(np.stack(uv, axis=1))
        fixed.append(np.full(i.size, 1 - axis))
    i, j = np.nonzero(F == 0)
    starts.append(np.stack([us[i], vs[j]], axis=1))
    fixed.append(np.full(i.size, 0))
    X0, k = np.concatenate(starts), np.concatenate(fixed)
    if len(X0) == 0:
        return X0
    C = np.zeros_like(X0)
    C[np.arange(len(k)), k] = 1.0
    Xs, _, ok = marching.newton(problem, X0, C, X0[np.arange(len(k)), k])
    return Xs[ok]


# -- public ---------------------------------------------------------------------------------


def plane_frame(origin, normal):
    """An orthonormal ``(origin, xdir, ydir, normal)`` frame of a plane (for plane (u, v))."""
    n = np.asarray(normal, dtype=float)
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    x = np.cross(helper, n)
    x /= np.linalg.norm(x)
    return np.asarray(origin, dtype=float), x, np.cross(n, x), n


def as_plane(value, name: str):
    """``(origin, unit normal)`` from ``(origin, normal)``, a build123d ``Plane`` or a
    surfmod plane surface (``PlaneSurface`` or ``ThreePointPlane``: its infinite carrier plane)."""
    if isinstance(value, (PlaneSurface, ThreePointPlane)):
        return np.array(value.origin), np.array(value.normal)
    if hasattr(value, "z_dir") and hasattr(value, "origin"):  # build123d Plane
        return checks.point(tuple(value.origin), f"{name}.origin"), checks.direction(tuple(value.z_dir), f"{name}.z_dir")
    try:
        origin, normal = value
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected a plane as (origin, normal), a build123d Plane or a plane surface, got {value!r}") from None
    return checks.point(origin, f"{name} origin"), checks.direction(normal, f"{name} normal")


def _is_plane_spec(value):
    if isinstance(value, Surface):
        return False
    return hasattr(value, "z_dir") or isinstance(value, (tuple, list))


#: samples per direction of the coincidence test done before tracing
_COINCIDENCE_SAMPLES = 17


def _coincide_over_region(s: Surface, distance, tol: float, near=None) -> bool:
    """True when a 2 x 2 block of neighbouring samples of ``s`` all lie within ``tol`` of
    the other object (``distance`` maps points to distances): a patch of ``s`` lies on
    it, so the intersection is a region, not a curve.  Touching along a curve or at a
    point never fills such a block.  ``near`` (points -> mask) is a cheap necessary
    condition; only the corners of blocks that pass it get an exact distance."""
    (u0, u1), (v0, v1) = s.domain
    n = _COINCIDENCE_SAMPLES
    pts = s.grid(np.linspace(u0, u1, n), np.linspace(v0, v1, n)).reshape(-1, 3)
    maybe = (np.ones(n * n, bool) if near is None else near(pts)).reshape(n, n)
    blocks = maybe[:-1, :-1] & maybe[1:, :-1] & maybe[:-1, 1:] & maybe[1:, 1:]
    if not blocks.any():
        return False
    corners = np.zeros((n, n), bool)
    for di in (0, 1):
        for dj in (0, 1):
            corners[di : n - 1 + di, dj : n - 1 + dj] |= blocks
    idx = np.nonzero(corners.ravel())[0]
    on = np.zeros(n * n, bool)
    on[idx] = distance(pts[idx]) <= tol
    on = on.reshape(n, n)
    return bool(np.any(on[:-1, :-1] & on[1:, :-1] & on[:-1, 1:] & on[1:, 1:]))


def _near_samples_of(s: Surface, tol: float):
    """Points -> mask of those within a sample cell of ``s`` (a point on ``s`` always is)."""
    _, _, _, _, pts, cell = _grid(s)
    return lambda p: np.linalg.norm(p - pts[nearest_samples(p, pts, 1)[:, 0]], axis=1) <= cell + tol


def _refuse_coincident(a, b, plane, tol: float, names) -> None:
    if plane is not None:
        o, n = plane
        hit = _coincide_over_region(a, lambda p: np.abs((p - o) @ n), tol)
    else:
        hit = _coincide_over_region(a, lambda p: closest_points(b, p, 2)[3], tol, _near_samples_of(b, tol)) or (
            _coincide_over_region(b, lambda p: closest_points(a, p, 2)[3], tol, _near_samples_of(a, tol))
        )
    if hit:
        raise SurfmodError(
            f"{names[0]}, {names[1]}: the surfaces coincide over a region (within tolerance {tol:g}); "
            "their intersection is that region, not a curve"
        )


def intersect(a, b, tolerance: float = 1e-6, *, step: float | None = None, max_angle: float = 4.0,
              max_points: int = 1_000_000, progress: bool = False) -> list[IntersectionCurve]:
    """Intersection curves of two surfaces, or of a surface and an infinite plane.

    ``b`` (or ``a``) may be a surfmod surface (a bounded patch, a ``PlaneSurface`` or
    ``ThreePointPlane`` included) or an infinite plane given as ``(origin, normal)`` / a build123d ``Plane``.
    A build123d / OCP face, or a face read back with :func:`surfmod.from_face`, is a
    trimmed surface: the curves are clipped to its boundary.
    Every returned point lies on both within ``tolerance`` (Newton converges to ~1e-12
    in practice); ``step`` bounds the 3-D step (default 1/40 of the model size) and
    ``max_angle`` (degrees) the turn of the tangent per step.  No intersection gives
    ``[]``.  Surfaces that coincide over a region (``intersect(s, s)``) raise
    ``SurfmodError`` ("the surfaces coincide over a region") before any tracing; a
    ``step`` so small that the curves would need more than ``max_points`` points (about
    ten model sizes of curve) is refused up front.  ``progress`` shows a tqdm bar over the
    seeds the tracing settles.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0))
    >>> [c] = sm.intersect(s, ((0.5, 0, 0), (1, 0, 0)))
    >>> round(c.length, 12), c.closed
    (2.0, False)
    >>> sm.intersect(s, ((0, 0, 5), (0, 0, 1)))
    []
    """
    tol = checks.positive(tolerance, "tolerance")
    angle = checks.real(max_angle, "max_angle", low=1e-3, high=90.0)
    # faces (build123d / OCP / read back) are trimmed surfaces: curves end at their boundary
    a, b = as_face_surface(a), as_face_surface(b)
    swap = _is_plane_spec(a) and isinstance(b, Surface)
    if swap:
        a, b = b, a
    a = require_surface(a, "b" if swap else "a")
    plane = None if isinstance(b, Surface) else as_plane(b, "a" if swap else "b")
    problem = SurfaceSurface(a, b, tol) if plane is None else SurfacePlane(a, *plane, tol)
    # below the floor Newton's stop test is never met and coincidence never detected
    tol = problem.tolerance = checks.tolerance(tol, "tolerance", problem.scale)
    h = checks.positive(step, "step") if step is not None else problem.scale / 40
    checks.work(10.0 * problem.scale / h, max_points, "max_points", f"tracing with step {h:.3g} on a model of size {problem.scale:.3g}")
    _refuse_coincident(a, b, plane, tol, ("b", "a") if swap else ("a", "b"))  # before any seed is solved
    if plane is None:
        seeds = _surface_surface_seeds(problem)
        uv_b_of = lambda X, P: X[:, 2:]  # noqa: E731
    else:
        origin, normal = plane
        seeds = implicit_seeds(problem, a)
        o, x, y, _ = plane_frame(origin, normal)
        uv_b_of = lambda X, P: np.stack([(P - o) @ x, (P - o) @ y], axis=1)  # noqa: E731

    with tqdm(total=len(seeds), desc="intersect", unit="seed", disable=not progress, leave=False) as bar:
        traced = marching.trace_all(problem, seeds, h, angle, bar)
    # drop slivers (a seed on a seam or at a tangency traced for a vanishing length)
    traced = [(X, c) for X, c in traced if np.ptp(problem.evaluate(X)[2], axis=0).max() > 1e-6 * problem.scale]
    curves = clip_curves(_curves(problem, traced, uv_b_of), a, b, IntersectionCurve)
    if swap:
        curves = [IntersectionCurve(c.points, c.uv_b, c.uv_a, c.tangents, c.closed) for c in curves]
    return curves


def intersect_line(s: Surface, origin, direction, *, tolerance: float = 1e-9) -> np.ndarray:
    """Where the line ``origin + t * unit(direction)`` meets ``s``: ``(k, 3)`` rows
    ``(u, v, t)`` sorted by ``t`` (``t`` is the signed distance from ``origin``); no hit
    gives an empty ``(0, 3)`` array.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0))
    >>> sm.intersect_line(s, (0.5, 1.0, 3.0), (0, 0, -2))
    array([[0.25, 0.5 , 3.  ]])
    """
    s = require_surface(s, "s")
    o = checks.point(origin, "origin")
    d = checks.direction(direction, "direction")
    tol = checks.tolerance(tolerance, "tolerance", seeded_size(s))
    problem = SurfaceLine(s, o, d, tol)
    _, _, uu, vv, pts, cell = _grid(s)
    rel = pts - o
    w = rel @ d
    dist = np.linalg.norm(rel - w[:, None] * d, axis=1)
    cand = np.nonzero(dist <= cell)[0]
    if cand.size == 0:
        return np.empty((0, 3))
    X, _, ok = marching.newton(problem, np.stack([uu[cand], vv[cand], w[cand]], axis=1), iterations=40)
    X = X[ok]
    if len(X) == 0:
        return np.empty((0, 3))
    X = X[np.lexsort((X[:, 1], X[:, 0], X[:, 2]))]
    # on a line, t fixes the point: equal t is one hit (poles and seams give several (u, v))
    dup = np.zeros(len(X), bool)
    dup[1:] = np.diff(X[:, 2]) <= 1e-9 * problem.scale
    return X[~dup]
