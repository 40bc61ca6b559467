"""The three forms of a surface, explicit ``z = f(x, y)`` (:func:`explicit`), implicit
``F(x, y, z) = 0`` (:func:`implicit`, :func:`to_implicit`) and parametric, and the
conversions between them where they exist.
See :doc:`/guide/surfaces` (section "The superellipsoid and the three forms").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..nets.knots import span_samples
from .fitting import FittedSurface, interpolate

_MAX_SAMPLES = 513


class ImplicitSurface:
    """An implicit surface ``F(x, y, z) = 0`` with gradient and normals.

    ``F`` takes three broadcastable arrays and returns their broadcast shape;
    ``gradient`` (optional, same call) returns the three partials (a tuple or an array
    with a trailing axis of 3); without it the gradient is taken by central differences
    with ``step`` (default ``1e-6`` times the size of ``bounds``, or ``1e-6``).
    ``bounds`` ``((x0, x1), (y0, y1), (z0, z1))`` is the region of interest.

    >>> import surfmod as sm, numpy as np
    >>> ball = sm.implicit(lambda x, y, z: x**2 + y**2 + z**2 - 4)
    >>> float(ball.value((2.0, 0.0, 0.0)))
    0.0
    >>> np.round(ball.normals((0.0, 2.0, 0.0)), 6)
    array([0., 1., 0.])
    """

    def __init__(self, F, bounds=None, gradient=None, step: float | None = None):
        if not callable(F):
            raise SurfmodError(f"F: expected a callable F(x, y, z), got {type(F).__name__}")
        if gradient is not None and not callable(gradient):
            raise SurfmodError(f"gradient: expected a callable or None, got {type(gradient).__name__}")
        self.F = F
        self._gradient = gradient
        if bounds is not None:
            b = checks.finite_array(bounds, "bounds")
            if b.shape != (3, 2) or np.any(b[:, 1] <= b[:, 0]):
                raise SurfmodError("bounds: expected ((x0, x1), (y0, y1), (z0, z1)) with x0 < x1 etc.")
            self.bounds = tuple((float(lo), float(hi)) for lo, hi in b)
        else:
            self.bounds = None
        if step is None:
            size = 1.0 if self.bounds is None else max(hi - lo for lo, hi in self.bounds)
            step = 1e-6 * size
        self.step = checks.positive(step, "step")

    @property
    def analytic_gradient(self) -> bool:
        """True when the gradient was given, False when it is numerical."""
        return self._gradient is not None

    def value(self, xyz) -> np.ndarray:
        """``F`` at points ``(..., 3)``."""
        p = checks.finite_array(xyz, "xyz", last=3)
        return self._value(p)

    __call__ = value

    def _value(self, p):
        out = np.asarray(self.F(p[..., 0], p[..., 1], p[..., 2]), dtype=float)
        return np.broadcast_to(out, p.shape[:-1]).copy()

    def gradient(self, xyz) -> np.ndarray:
        """``∇F`` at points ``(..., 3)``: analytic if given, else central differences."""
        p = checks.finite_array(xyz, "xyz", last=3)
        if self._gradient is not None:
            g = self._gradient(p[..., 0], p[..., 1], p[..., 2])
            g = np.stack(np.broadcast_arrays(*g), axis=-1) if isinstance(g, (tuple, list)) else np.asarray(g, float)
            return np.broadcast_to(g, p.shape).astype(float)
        h = self.step
        out = np.empty(p.shape)
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            out[..., k] = (self._value(p + e) - self._value(p - e)) / (2 * h)
        return out

    def normals(self, xyz) -> np.ndarray:
        """Unit normals ``∇F / |∇F|`` (pointing to ``F > 0``)."""
        g = self.gradient(xyz)
        norm = np.linalg.norm(g, axis=-1, keepdims=True)
        if np.any(norm == 0):
            raise SurfmodError("xyz: the gradient vanishes at a point, the normal is undefined there")
        return g / norm

    def distance_estimate(self, xyz) -> np.ndarray:
        """First-order signed distance ``F / |∇F|`` (exact for a plane)."""
        p = checks.finite_array(xyz, "xyz", last=3)
        return self._value(p) / np.linalg.norm(self.gradient(p), axis=-1)

    def project(self, xyz, iterations: int = 30) -> np.ndarray:
        """Points moved onto ``F = 0`` along the gradient (Newton steps
        ``x -= F ∇F / |∇F|²``), vectorized over the points.

        >>> import surfmod as sm, numpy as np
        >>> ball = sm.implicit(lambda x, y, z: x**2 + y**2 + z**2 - 4)
        >>> np.round(ball.project((3.0, 0.0, 0.0)), 12)
        array([2., 0., 0.])
        """
        p = checks.finite_array(xyz, "xyz", last=3).copy()
        for _ in range(checks.count(iterations, "iterations")):
            g = self.gradient(p)
            g2 = np.sum(g * g, axis=-1, keepdims=True)
            step = self._value(p)[..., None] * g / np.where(g2 > 0, g2, np.inf)
            p = p - step
            if np.max(np.abs(step)) <= 1e-15 * max(1.0, float(np.abs(p).max())):
                break
        return p

    def to_explicit(self, x_range, y_range, z0: float = 0.0, tolerance: float | None = None):
        """The explicit form ``z = f(x, y)`` of the sheet of ``F = 0`` through the start
        height ``z0``, where it exists (``∂F/∂z ≠ 0`` over the rectangle): ``f`` solves
        ``F(x, y, f) = 0`` by vectorized Newton steps in ``z``, and the result is fitted
        by :func:`explicit` within ``tolerance``.

        >>> import surfmod as sm, numpy as np
        >>> ball = sm.implicit(lambda x, y, z: x**2 + y**2 + z**2 - 4)
        >>> cap = ball.to_explicit((-1, 1), (-1, 1), z0=2.0, tolerance=1e-6)
        >>> round(float(cap.height(0.0, 0.0)), 12), bool(cap.max_deviation <= 1e-6)
        (2.0, True)
        """
        z_start = float(checks.finite_array(z0, "z0"))

        def height(x, y):
            x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
            z = np.full(x.shape, z_start)
            for _ in range(60):
                p = np.stack([x, y, z], axis=-1)
                fz = self.gradient(p)[..., 2]
                if np.any(np.abs(fz) < 1e-300):
                    raise SurfmodError("z0: dF/dz vanishes, no explicit form z = f(x, y) there")
                step = self._value(p) / fz
                z = z - step
                if np.max(np.abs(step)) <= 1e-14 * max(1.0, float(np.abs(z).max())):
                    break
            else:
                raise SurfmodError("z0: Newton's method for z did not converge; no explicit form from this start")
            return z

        return explicit(height, x_range, y_range, tolerance)


def implicit(F, bounds=None, gradient=None, step: float | None = None) -> ImplicitSurface:
    """An :class:`ImplicitSurface` ``F(x, y, z) = 0`` (see there).

    >>> import surfmod as sm
    >>> s = sm.implicit(lambda x, y, z: z - x * y, gradient=lambda x, y, z: (-y, -x, 1.0 + 0 * z))
    >>> s.gradient((1.0, 2.0, 2.0)).tolist()
    [-2.0, -1.0, 1.0]
    """
    return ImplicitSurface(F, bounds, gradient, step)


class ExplicitSurface(FittedSurface):
    """``z = f(x, y)`` fitted by a bicubic B-spline with parameters ``u = x``, ``v = y``.

    Attributes: ``f``, ``x_range``, ``y_range``, ``tolerance`` (requested), ``max_deviation``
    (measured ``max |z_spline - f|`` on a grid three times finer than the samples) and
    ``samples``.

    >>> import surfmod as sm
    >>> s = sm.explicit(lambda x, y: x * y, (0, 1), (0, 1))
    >>> float(s.height(0.5, 0.5)), s.parametric(1.0, 2.0).tolist()
    (0.25, [1.0, 2.0, 2.0])
    """

    occt_construct = "Geom_BSplineSurface (bicubic fit of z = f(x, y))"

    def height(self, x, y) -> np.ndarray:
        """The exact ``f(x, y)``."""
        return _call_f(self.f, np.asarray(x, dtype=float), np.asarray(y, dtype=float))

    def parametric(self, x, y) -> np.ndarray:
        """The exact parametric form ``(x, y, f(x, y))``."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return np.stack([x, y, self.height(x, y)], axis=-1)

    def to_implicit(self) -> ImplicitSurface:
        """``F(x, y, z) = z - f(x, y)`` with a numerical gradient."""
        f = self.f
        (x0, x1), (y0, y1) = self.x_range, self.y_range
        z = self.control_points[..., 2]
        zb = (float(z.min()) - 1.0, float(z.max()) + 1.0)
        return ImplicitSurface(lambda x, y, zz: zz - f(x, y), bounds=((x0, x1), (y0, y1), zb))


def _call_f(f, x, y):
    try:
        with np.errstate(all="ignore"):
            z = np.asarray(f(x, y), dtype=float)
    except SurfmodError:
        raise
    except Exception as exc:
        raise SurfmodError(f"f: raised {type(exc).__name__}: {exc}") from None
    try:
        z = np.broadcast_to(z, np.broadcast(x, y).shape)
    except ValueError:
        raise SurfmodError(f"f: must return an array shaped like its inputs, got shape {z.shape}") from None
    bad = ~np.isfinite(z)
    if np.any(bad):
        xb, yb = np.broadcast_arrays(x, y)
        i = np.argwhere(bad)[0]
        raise SurfmodError(
            f"f: returned {z[tuple(i)]} (not finite) at (x, y) = ({xb[tuple(i)]:g}, {yb[tuple(i)]:g})"
        )
    return z


def explicit(f, x_range, y_range, tolerance: float | None = None) -> ExplicitSurface:
    """The explicit surface ``z = f(x, y)`` over ``x_range x y_range`` as a bicubic B-spline.

    ``f`` is called with NumPy arrays (vectorized).  The sample grid is refined (per
    direction) until ``max |z_spline - f|`` measured on a three-times finer grid is at
    most ``tolerance`` (default ``1e-3`` times the largest extent of the samples).  A
    non-finite value of ``f`` raises :class:`SurfmodError` naming the point.

    >>> import numpy as np, surfmod as sm
    >>> s = sm.explicit(lambda x, y: np.sin(x) * np.cos(y), (0, 3), (0, 2), tolerance=1e-5)
    >>> s.max_deviation <= 1e-5
    True
    >>> s.points(1.0, 0.5)[:2].round(12).tolist()
    [1.0, 0.5]
    """
    if not callable(f):
        raise SurfmodError(f"f: expected a callable f(x, y), got {type(f).__name__}")
    (x0, x1), (y0, y1) = checks.interval(x_range, "x_range"), checks.interval(y_range, "y_range")
    nx = ny = 9
    xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
    z0 = _call_f(f, xs[:, None], ys[None, :])
    size = max(x1 - x0, y1 - y0, float(z0.max() - z0.min()))
    tol = 1e-3 * size if tolerance is None else checks.tolerance(tolerance, "tolerance", size)
    while True:
        xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
        z = _call_f(f, xs[:, None], ys[None, :])
        pts = np.stack(np.broadcast_arrays(xs[:, None], ys[None, :], z), axis=-1)
        fit = interpolate(pts, (3, 3), parameters=(xs, ys))
        xe, ye = span_samples(xs, 3), span_samples(ys, 3)
        err = np.abs(fit.grid(xe, ye)[..., 2] - _call_f(f, xe[:, None], ye[None, :]))
        max_err = float(err.max())
        if max_err <= tol:
            break
        if nx >= _MAX_SAMPLES and ny >= _MAX_SAMPLES:
            raise SurfmodError(f"tolerance: could not fit within {tol:g} (reached {max_err:g} with {nx} x {ny} samples)")
        # refine the direction whose mid-span errors dominate (both when they are close)
        eu = float(err[1::3, ::3].max()) if err.shape[0] > 1 else 0.0
        ev = float(err[::3, 1::3].max()) if err.shape[1] > 1 else 0.0
        if eu >= 0.5 * ev or ny >= _MAX_SAMPLES:
            nx = min(_MAX_SAMPLES, 2 * nx - 1)
        if ev >= 0.5 * eu or nx >= _MAX_SAMPLES:
            ny = min(_MAX_SAMPLES, 2 * ny - 1)
    fields = {**fit.__dict__, "f": f, "x_range": (x0, x1), "y_range": (y0, y1), "tolerance_requested": tol}
    return ExplicitSurface._construct_fast(**{**fields, "max_deviation": max_err, "samples": (nx, ny)})


def to_implicit(surface) -> ImplicitSurface:
    """The implicit form of a surface where it is known.

    Explicit surfaces give ``z - f(x, y)``; surfaces with an ``implicit_surface()``
    method (superellipsoid) give theirs; surfaces with an ``implicit(xyz)`` method
    (planes, quadrics) are wrapped with a numerical gradient.  Anything else raises
    :class:`SurfmodError`: a general parametric surface has no closed implicit form.

    >>> import surfmod as sm
    >>> F = sm.to_implicit(sm.plane((0, 0, 1), (1, 0, 1), (0, 1, 1)))
    >>> float(F.value((5.0, 7.0, 1.0)))
    0.0
    """
    if isinstance(surface, ImplicitSurface):
        return surface
    if isinstance(surface, ExplicitSurface):
        return surface.to_implicit()
    make = getattr(surface, "implicit_surface", None)
    if callable(make):
        return make()
    fn = getattr(surface, "implicit", None)
    if callable(fn):
        return ImplicitSurface(lambda x, y, z: fn(np.stack(np.broadcast_arrays(x, y, z), axis=-1)))
    raise SurfmodError(f"surface: no implicit form is known for {type(surface).__name__}")
