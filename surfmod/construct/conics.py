"""Conics as curve inputs: ``Circle``, ``Arc``, ``Ellipse`` (OCCT's angle parametrization),
``Parabola`` and ``Hyperbola``; straight lines are ``construct/curves.Line``.

A conic with centre ``C``, frame ``(X, Y = N x X)`` and semi-axes ``a, b`` is
``C + a cos t X + b sin t Y`` with ``t`` in radians, exactly ``Geom_Circle`` /
``Geom_Ellipse`` on ``gp_Ax2(C, N, X)``; when ``X`` is not given it is chosen by OCCT's
own ``gp_Ax2(C, N)`` rule.  ``to_bspline()`` is the exact rational quadratic NURBS
(at most 90 degrees per Bézier segment, middle weights ``cos(delta/2)``) on the same
parameter interval; its parametrization differs from the angle (same points as a set).
"""

from __future__ import annotations

import math

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve
from .axes import cos_d, frame_transformed, make_frame, sin_d

TWO_PI = 2.0 * math.pi


def arc_segments(t0: float, t1: float) -> tuple:
    """``(theta, scale, weights, knots)`` of the rational quadratic B-spline of the unit
    circle over ``[t0, t1]`` (radians), in arcs of at most 90 degrees: the poles lie at
    the angles ``theta``, ``scale`` from the centre; knots on ``[t0, t1]``."""
    span = t1 - t0
    nseg = max(1, int(math.ceil(abs(span) / (math.pi / 2) - 1e-9)))
    delta = span / nseg
    half = math.cos(delta / 2.0)
    odd = np.arange(2 * nseg + 1) % 2 == 1
    theta = t0 + np.arange(2 * nseg + 1) * (delta / 2.0)
    knots = np.concatenate([[t0] * 3, np.repeat(t0 + delta * np.arange(1, nseg), 2), [t1] * 3])
    return theta, np.where(odd, 1.0 / half, 1.0), np.where(odd, half, 1.0), knots


def arc_bspline(center, x_axis, y_axis, t0: float, t1: float) -> BSplineCurve:
    """Exact rational quadratic B-spline of ``center + cos t x_axis + sin t y_axis`` for
    ``t`` in ``[t0, t1]`` (axes carry the semi-axis lengths); knots on ``[t0, t1]``."""
    theta, scale, w, knots = arc_segments(t0, t1)
    pts = center + (np.cos(theta) * scale)[:, None] * x_axis + (np.sin(theta) * scale)[:, None] * y_axis
    return BSplineCurve._trusted(pts, 2, knots, w)


class Conic(Curve):
    """``C + a cos t X + b sin t Y`` over a range of ``t`` (radians); base of Circle/Arc/Ellipse."""

    def _init(self, center, normal, x_dir, a, b, t_range):
        self.center = checks.frozen(center)
        self.normal = checks.frozen(normal)
        self.x_dir = checks.frozen(x_dir)
        self.y_dir = checks.frozen(np.cross(normal, x_dir))
        self.a, self.b = float(a), float(b)
        self._domain = (float(t_range[0]), float(t_range[1]))

    @classmethod
    def _from_radians(cls, center, normal, x_dir, a, b, t_range):
        """Trusted constructor (readers, surfaces): a circle arc when ``a == b``."""
        target = Arc if (cls is Conic and a == b) else (Ellipse if cls is Conic else cls)
        obj = target._construct_fast()
        Conic._init(obj, np.asarray(center, float), np.asarray(normal, float), np.asarray(x_dir, float), a, b, t_range)
        return obj

    @property
    def domain(self):
        return self._domain

    @property
    def is_full(self) -> bool:
        t0, t1 = self._domain
        return abs(t0) < 1e-15 and abs(t1 - TWO_PI) < 1e-12

    def _derivatives(self, t, order):
        out = np.empty((t.size, order + 1, 3))
        for k in range(order + 1):
            out[:, k] = (self.a * cos_d(t, k))[:, None] * self.x_dir + (self.b * sin_d(t, k))[:, None] * self.y_dir
        out[:, 0] += self.center
        return out

    def _basis_geom(self):
        from ..occ.analytic import conic

        if self.a == self.b:
            return conic("circle", self.center, self.normal, self.x_dir, self.a)
        if self.a >= self.b:
            return conic("ellipse", self.center, self.normal, self.x_dir, self.a, self.b)
        raise SurfmodError("ellipse: OCCT needs the major radius along X (a >= b)")

    def geom(self):
        """``Geom_Circle``/``Geom_Ellipse`` (full) or its ``Geom_TrimmedCurve``."""
        from ..occ.analytic import trimmed

        basis = self._basis_geom()
        return basis if self.is_full else trimmed(basis, *self._domain)

    def to_bspline(self) -> BSplineCurve:
        """Exact rational quadratic NURBS over the same parameter interval.

        >>> import numpy as np, surfmod as sm
        >>> c = sm.Circle((0, 0, 0), (0, 0, 1), 2.0).to_bspline()
        >>> bool(np.allclose(np.linalg.norm(c.points(np.linspace(0, 6.2, 7)), axis=1), 2.0))
        True
        """
        t0, t1 = self._domain
        return arc_bspline(self.center, self.a * self.x_dir, self.b * self.y_dir, t0, t1)

    def transformed(self, matrix):
        """Similarity maps keep the conic (frame moved, radii scaled); other affine maps
        return the mapped exact NURBS."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_bspline().transformed(m)
        (c, x, y, _), s = frame_transformed((self.center, self.x_dir, self.y_dir, self.normal), m)
        return type(self)._from_radians(c, np.cross(x, y), x, self.a * s, self.b * s, self._domain)

    def implicit(self, xyz) -> np.ndarray:
        """``(x/a)^2 + (y/b)^2 - 1`` in the conic's plane frame (in-plane test only)."""
        d = np.asarray(xyz, dtype=float) - self.center
        return (d @ self.x_dir / self.a) ** 2 + (d @ self.y_dir / self.b) ** 2 - 1.0


class Circle(Conic):
    """Full circle ``C + r (cos t X + sin t Y)``, ``t`` in ``[0, 2 pi]`` (``Geom_Circle``).

    >>> import surfmod as sm
    >>> c = sm.Circle((0, 0, 0), (0, 0, 1), 2.0)
    >>> c.points(0.0), c.domain
    (array([2., 0., 0.]), (0.0, 6.283185307179586))
    """

    occt_construct = "Geom_Circle"

    def __init__(self, center, normal, radius, x_dir=None):
        c, x, _, n = make_frame(center, normal, x_dir, axis_name="normal")
        r = checks.positive(radius, "radius")
        self._init(c, n, x, r, r, (0.0, TWO_PI))

    @property
    def radius(self) -> float:
        return self.a


class Arc(Conic):
    """Circular arc from ``start_angle`` to ``end_angle`` (degrees, measured from ``x_dir``
    about ``normal``), parametrized by the angle in radians like ``Geom_TrimmedCurve`` of a
    ``Geom_Circle``: the domain starts at ``start_angle`` brought into ``[0, 360)``.

    >>> import surfmod as sm
    >>> a = sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 0, 90)
    >>> a.points(a.domain[1]).round(12)
    array([0., 1., 0.])
    """

    occt_construct = "Geom_TrimmedCurve(Geom_Circle)"

    def __init__(self, center, normal, radius, start_angle, end_angle, x_dir=None):
        c, x, _, n = make_frame(center, normal, x_dir, axis_name="normal")
        r = checks.positive(radius, "radius")
        a0 = checks.angle(start_angle, "start_angle")
        a1 = checks.angle(end_angle, "end_angle")
        span = math.radians(a1 - a0)
        if not 0.0 < span <= TWO_PI + 1e-12:
            raise SurfmodError(f"end_angle: must exceed start_angle by (0, 360] degrees, got {a0:g} -> {a1:g}")
        t0 = math.radians(a0) % TWO_PI
        self._init(c, n, x, r, r, (t0, t0 + min(span, TWO_PI)))

    @property
    def radius(self) -> float:
        return self.a

    @classmethod
    def through(cls, p0, p1, p2) -> "Arc":
        """The arc from ``p0`` through ``p1`` to ``p2``.

        >>> import surfmod as sm
        >>> a = sm.Arc.through((1, 0, 0), (0, 1, 0), (-1, 0, 0))
        >>> round(a.radius, 12), a.center.round(12).tolist()
        (1.0, [0.0, 0.0, 0.0])
        """
        a, b, c = checks.point(p0, "p0"), checks.point(p1, "p1"), checks.point(p2, "p2")
        ab, ac = b - a, c - a
        n = np.cross(ab, ac)
        scale = max(np.linalg.norm(ab), np.linalg.norm(ac))
        if np.linalg.norm(ab) <= 1e-12 * max(scale, 1.0):
            raise SurfmodError("p1: coincides with p0")
        if np.linalg.norm(n) <= 1e-12 * scale * scale:
            raise SurfmodError("p2: collinear with p0 and p1, no arc passes through them")
        # circumcentre
        nn = float(np.dot(n, n))
        center = a + (np.dot(ac, ac) * np.cross(n, ab) + np.dot(ab, ab) * np.cross(ac, n)) / (2.0 * nn)
        normal = n / np.sqrt(nn)
        x = (a - center) / np.linalg.norm(a - center)
        y = np.cross(normal, x)
        end = math.atan2(float((c - center) @ y), float((c - center) @ x)) % TWO_PI
        r = float(np.linalg.norm(a - center))
        return cls._from_radians(center, normal, x, r, r, (0.0, end))


class Ellipse(Conic):
    """Full ellipse ``C + a cos t X + b sin t Y`` (``Geom_Ellipse``, ``a >= b``).

    >>> import surfmod as sm
    >>> sm.Ellipse((0, 0, 0), (0, 0, 1), 3.0, 1.0).points(0.0)
    array([3., 0., 0.])
    """

    occt_construct = "Geom_Ellipse"

    def __init__(self, center, normal, major, minor, x_dir=None):
        c, x, _, n = make_frame(center, normal, x_dir, axis_name="normal")
        a, b = checks.positive(major, "major"), checks.positive(minor, "minor")
        if b > a:
            raise SurfmodError(f"minor: must not exceed major ({a:g}), got {b:g}")
        self._init(c, n, x, a, b, (0.0, TWO_PI))


class _FramedCurve(Curve):
    """Shared frame handling of Parabola and Hyperbola (planar, ``Y = N x X``)."""

    def _init(self, center, normal, x_dir, params, t_range):
        self.center = checks.frozen(center)
        self.normal = checks.frozen(normal)
        self.x_dir = checks.frozen(x_dir)
        self.y_dir = checks.frozen(np.cross(normal, x_dir))
        self._set_params(*params)
        self._domain = checks.interval(t_range, "t_range")

    @classmethod
    def _make(cls, center, normal, x_dir, params, t_range):
        obj = cls._construct_fast()
        obj._init(*(np.asarray(a, float) for a in (center, normal, x_dir)), params, t_range)
        return obj

    @property
    def domain(self):
        return self._domain

    def _derivatives(self, t, order):
        fx, fy = self._coefficients(t, order)
        out = fx[..., None] * self.x_dir + fy[..., None] * self.y_dir
        out[:, 0] += self.center
        return out

    def geom(self):
        from ..occ.analytic import trimmed

        return trimmed(self._basis_geom(), *self._domain)

    def transformed(self, matrix):
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_bspline().transformed(m)
        (c, x, y, _), s = frame_transformed((self.center, self.x_dir, self.y_dir, self.normal), m)
        params, t_scale = self._scaled(s)
        t0, t1 = self._domain
        return type(self)._make(c, np.cross(x, y), x, params, (t0 * t_scale, t1 * t_scale))


class Parabola(_FramedCurve):
    """``Geom_Parabola``: ``C + t^2 / (4 f) X + t Y`` over ``t_range`` (``f`` focal length).

    >>> import surfmod as sm
    >>> sm.Parabola((0, 0, 0), (0, 0, 1), 0.25, (-1, 1)).points(1.0)
    array([1., 1., 0.])
    """

    occt_construct = "Geom_TrimmedCurve(Geom_Parabola)"

    def __init__(self, center, normal, focal, t_range, x_dir=None):
        c, x, _, n = make_frame(center, normal, x_dir, axis_name="normal")
        self._init(c, n, x, (checks.positive(focal, "focal"),), t_range)

    def _set_params(self, focal):
        self.focal = float(focal)

    def _scaled(self, s):
        return (self.focal * s,), s

    def _coefficients(self, t, order):
        fx, fy = np.zeros((t.size, order + 1)), np.zeros((t.size, order + 1))
        fx[:, 0], fy[:, 0] = t * t / (4 * self.focal), t
        if order >= 1:
            fx[:, 1], fy[:, 1] = t / (2 * self.focal), 1.0
        if order >= 2:
            fx[:, 2] = 1.0 / (2 * self.focal)
        return fx, fy

    def _basis_geom(self):
        from ..occ.analytic import conic

        return conic("parabola", self.center, self.normal, self.x_dir, self.focal)

    def to_bspline(self) -> BSplineCurve:
        """The exact quadratic Bézier (same parametrization: the parabola is polynomial)."""
        t0, t1 = self._domain
        d = self._derivatives(np.array([t0, t1]), 1)
        pts = np.array([d[0, 0], d[0, 0] + 0.5 * (t1 - t0) * d[0, 1], d[1, 0]])
        return BSplineCurve._trusted(pts, 2, np.array([t0, t0, t0, t1, t1, t1]))


class Hyperbola(_FramedCurve):
    """``Geom_Hyperbola``: ``C + a cosh t X + b sinh t Y`` over ``t_range``.

    >>> import surfmod as sm
    >>> sm.Hyperbola((0, 0, 0), (0, 0, 1), 2.0, 1.0, (-1, 1)).points(0.0)
    array([2., 0., 0.])
    """

    occt_construct = "Geom_TrimmedCurve(Geom_Hyperbola)"

    def __init__(self, center, normal, major, minor, t_range, x_dir=None):
        c, x, _, n = make_frame(center, normal, x_dir, axis_name="normal")
        self._init(c, n, x, (checks.positive(major, "major"), checks.positive(minor, "minor")), t_range)

    def _set_params(self, major, minor):
        self.a, self.b = float(major), float(minor)

    def _scaled(self, s):
        return (self.a * s, self.b * s), 1.0

    def _coefficients(self, t, order):
        fx, fy = np.empty((t.size, order + 1)), np.empty((t.size, order + 1))
        ch, sh = np.cosh(t), np.sinh(t)
        for k in range(order + 1):
            fx[:, k] = self.a * (ch if k % 2 == 0 else sh)
            fy[:, k] = self.b * (sh if k % 2 == 0 else ch)
        return fx, fy

    def _basis_geom(self):
        from ..occ.analytic import conic

        return conic("hyperbola", self.center, self.normal, self.x_dir, self.a, self.b)

    def to_bspline(self) -> BSplineCurve:
        """Exact rational quadratic (one segment, middle weight ``cosh((t1 - t0) / 2)``)."""
        t0, t1 = self._domain
        tm, w = 0.5 * (t0 + t1), math.cosh(0.5 * (t1 - t0))
        mid = self.center + (self.a * math.cosh(tm) * self.x_dir + self.b * math.sinh(tm) * self.y_dir) / w
        ends = self.points(np.array([t0, t1]))
        return BSplineCurve._trusted(np.array([ends[0], mid, ends[1]]), 2, np.array([t0, t0, t0, t1, t1, t1]), np.array([1.0, w, 1.0]))
