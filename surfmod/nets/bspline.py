"""B-spline and NURBS curves and tensor-product surfaces (frozen values).

Knot vectors are *full* (flat) vectors, as in the textbooks and scipy: ``n + p + 1``
non-decreasing values for ``n`` control points of degree ``p``.  Clamped and unclamped
vectors are both accepted; the parameter domain is ``[knots[p], knots[n]]``, exactly as
OCCT's ``FirstParameter``/``LastParameter``.  Rational splines keep Cartesian control
points plus weights; evaluation works on homogeneous points ``(w x, w y, w z, w)``.
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..eval import derivative_nets, local
from ..eval.basis import basis_matrix
from ..eval.rational import curve_quotient
from ..eval.tensor import curve_derivatives
from ..surface import Surface
from . import knots as kn


def homogeneous(points: np.ndarray, weights: np.ndarray | None) -> np.ndarray:
    """``(..., 3)`` points -> ``(..., 4)`` homogeneous points (or the points themselves)."""
    if weights is None:
        return np.ascontiguousarray(points)
    return np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)


def cartesian(hpoints: np.ndarray, rational: bool):
    """Inverse of :func:`homogeneous`: ``(points, weights or None)``."""
    if not rational:
        return hpoints, None
    w = hpoints[..., 3]
    return hpoints[..., :3] / w[..., None], w


def uniform_clamped_knots(n_ctrl: int, degree: int) -> np.ndarray:
    """Clamped knots with equally spaced interior knots on ``[0, 1]``."""
    inner = np.linspace(0.0, 1.0, n_ctrl - degree + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


class BSplineCurve(Curve):
    """A B-spline or NURBS curve.

    >>> import surfmod as sm
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0)], 2, [0, 0, 0, 1, 1, 1])
    >>> c.points(0.5)
    array([1. , 0.5, 0. ])
    """

    occt_construct = "Geom_BSplineCurve"

    def __init__(self, points, degree: int, knots=None, weights=None):
        pts = checks.finite_array(points, "points", ndim=2, last=3)
        if pts.shape[0] < 2:
            raise SurfmodError(f"points: need at least 2 control points, got {pts.shape[0]}")
        p = checks.degree(degree, "degree", pts.shape[0])
        k = uniform_clamped_knots(pts.shape[0], p) if knots is None else checks.knot_vector(knots, p, pts.shape[0])
        w = checks.weights_for(weights, pts.shape[:1])
        self._set(pts, p, k, w)

    def _set(self, pts, p, k, w):
        self.control_points = checks.frozen(pts)
        self.degree = p
        self.knots = checks.frozen(k)
        self.weights = None if w is None else checks.frozen(w)
        self._homogeneous = homogeneous(self.control_points, self.weights)
        # a curve far from the origin is evaluated about its centre (eval.local.prepare)
        centre = local.far_centre(self.control_points)
        self._centred = (None if centre is None else
                         (centre, local.moved_homogeneous(self.control_points, self.weights, centre)))

    @classmethod
    def _trusted(cls, pts, p, k, w=None):
        """Build without re-validating (data produced inside surfmod)."""
        obj = cls._construct_fast()
        BSplineCurve._set(obj, pts, p, k, w)
        return obj

    @property
    def rational(self) -> bool:
        return self.weights is not None

    @property
    def domain(self):
        n = self.control_points.shape[0]
        return float(self.knots[self.degree]), float(self.knots[n])

    @property
    def breaks(self):
        return np.unique(self.knots[self.degree : len(self.control_points) + 1])

    def _derivatives(self, t, order):
        centre, net = self._centred or (None, self._homogeneous)
        if order > 0 and derivative_nets.crowded(self.knots, self.degree, [0.0, 1.0], 0):
            # crowded knots: each derivative from its derivative net (eval/derivative_nets.py)
            cartesian = None if self.weights is None else (self.control_points, self.weights,
                                                           np.zeros(3) if centre is None else centre)
            h = derivative_nets.curve_from_nets(self.knots, self.degree, net if self.rational else
                                                  self._homogeneous, t, order, cartesian, positions=net)
        else:
            h = curve_derivatives(self.knots, self.degree, net, t, order)
        out = curve_quotient(h) if self.rational else h
        if centre is not None:
            out[:, 0] += centre
        return out

    def geom(self):
        from ..occ.geom import bspline_curve

        return bspline_curve(self.control_points, self.degree, self.knots, self.weights)

    def transformed(self, matrix):
        m = transforms.affine(matrix)
        return BSplineCurve._trusted(transforms.apply(m, self.control_points), self.degree, self.knots, self.weights)

    def to_bspline(self):
        return self

    def insert_knot(self, t: float, times: int = 1) -> "BSplineCurve":
        """The same curve with ``t`` inserted ``times`` times (Boehm)."""
        t = float(checks.parameters(t, "t", self.domain))
        times = checks.count(times, "times")
        if kn.multiplicity(self.knots, t) + times > self.degree:
            raise SurfmodError(f"times: multiplicity of {t:g} would exceed the degree {self.degree}")
        return self._rebuilt(*kn.insert_knot(self.knots, self.degree, self._homogeneous, t, times))

    def segment(self, t0: float, t1: float) -> "BSplineCurve":
        """The exact piece over ``[t0, t1]`` (clamped), like OCCT's ``Segment``."""
        a, b = _ordered_range((t0, t1), "t_range", self.domain)
        return self._rebuilt(*kn.segment(self.knots, self.degree, self._homogeneous, a, b))

    def _rebuilt(self, knots, h):
        pts, w = cartesian(h, self.rational)
        return BSplineCurve._trusted(pts, self.degree, knots, w)


def _ordered_range(rng, name, domain):
    try:
        a, b = (float(x) for x in rng)
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected two numbers (start, end), got {rng!r}") from None
    a, b = checks.parameters(np.array([a, b]), name, domain)
    if not b > a:
        raise SurfmodError(f"{name}: start {a:g} must be below end {b:g}")
    return float(a), float(b)


class BSplineSurface(Surface):
    """A tensor-product B-spline or NURBS surface.

    ``control_points`` is ``(n, m, 3)``, ``degree = (p, q)``, ``knots = (U, V)`` full
    non-decreasing vectors of lengths ``n + p + 1`` and ``m + q + 1`` (clamped uniform
    knots on [0, 1] when omitted), ``weights`` ``(n, m)`` > 0 makes it a NURBS.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> s = sm.BSplineSurface(net, (3, 3))
    >>> s.points(0.5, 0.5)
    array([1.5, 1.5, 0. ])
    """

    occt_construct = "Geom_BSplineSurface"

    def __init__(self, control_points, degree=(3, 3), knots=None, weights=None):
        net = checks.control_net(control_points)
        n, m = net.shape[:2]
        p, q = _pair(degree, "degree")
        p = checks.degree(p, "degree[0] (u)", n)
        q = checks.degree(q, "degree[1] (v)", m)
        if knots is None:
            ku, kv = uniform_clamped_knots(n, p), uniform_clamped_knots(m, q)
        else:
            ku, kv = _pair(knots, "knots")
            ku = checks.knot_vector(ku, p, n, "knots[0] (U)")
            kv = checks.knot_vector(kv, q, m, "knots[1] (V)")
        w = checks.weights_for(weights, (n, m))
        self._set(net, (p, q), (ku, kv), w)

    def _set(self, net, degree, knots, w):
        self.control_points = checks.frozen(net)
        self.degree = (int(degree[0]), int(degree[1]))
        self.knots = (checks.frozen(knots[0]), checks.frozen(knots[1]))
        self.weights = None if w is None else checks.frozen(w)
        self._homogeneous = homogeneous(self.control_points, self.weights)
        self.__dict__.pop("_local", None)  # kernel tables (_local_net) follow the data

    @classmethod
    def _trusted(cls, net, degree, knots, weights=None):
        """Build without re-validating (data produced inside surfmod)."""
        obj = cls._construct_fast()
        BSplineSurface._set(obj, net, degree, knots, weights)
        return obj

    @classmethod
    def uniform_cubic(cls, control_points) -> "BSplineSurface":
        """The lecture's uniform cubic B-spline surface.

        Uniform, *unclamped* knots ``-3, -2, ..., n`` in each direction, so the domain is
        ``[0, n-3] x [0, m-3]`` and patch ``(i, j)`` covers ``[i, i+1] x [j, j+1]`` with
        local parameters ``s = u - i``, ``t = v - j`` in the matrix form
        ``[s^3 s^2 s 1] (1/6) M P M^T [t^3 t^2 t 1]^T``.

        >>> import numpy as np, surfmod as sm
        >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
        >>> sm.BSplineSurface.uniform_cubic(net).points(0.0, 0.0)
        array([1., 1., 0.])
        """
        net = checks.control_net(control_points)
        n, m = net.shape[:2]
        if n < 4 or m < 4:
            raise SurfmodError(f"control_points: a uniform cubic B-spline needs at least 4 x 4 points, got {n} x {m}")
        ku = np.arange(-3.0, n + 1.0)
        kv = np.arange(-3.0, m + 1.0)
        return cls._trusted(net, (3, 3), (ku, kv))

    @property
    def rational(self) -> bool:
        return self.weights is not None

    def __repr__(self):
        n, m = self.control_points.shape[:2]
        kind = "NURBS" if self.rational else "B-spline"
        return (f"{type(self).__name__}({kind}, {n}x{m} net, degree={self.degree}, "
                f"knots=({np.array2string(self.knots[0], precision=17, separator=',')}, "
                f"{np.array2string(self.knots[1], precision=17, separator=',')}))")

    @property
    def domain(self):
        (p, q), (ku, kv) = self.degree, self.knots
        n, m = self.control_points.shape[:2]
        return (float(ku[p]), float(ku[n])), (float(kv[q]), float(kv[m]))

    def _local_net(self) -> "local.LocalNet":
        """The net and tables as the compiled kernels take them, built once per surface."""
        cached = self.__dict__.get("_local")
        if cached is None:
            (p, q), (ku, kv) = self.degree, self.knots
            cached = self._local = local.prepare(ku, p, kv, q, self._homogeneous, self.control_points,
                                                    self.weights)
        return cached

    def _finite_partials(self, order: int) -> bool:
        return local.partials_finite(self._local_net(), order)

    def _derivatives(self, u, v, order):
        # local support: each point touches its (p+1) x (q+1) poles only (eval/local.py)
        if order == 0:
            return local.surface_points(self._local_net(), u, v)[:, None, None, :]
        return local.surface_derivatives(self._local_net(), u, v, order)

    def _grid_derivatives(self, us, vs, order):
        return local.surface_grid(self._local_net(), us, vs, order)

    def grid_into(self, us, vs, out, order: int = 0) -> np.ndarray:
        """Positions (``order=0``) or partials on the grid ``us x vs`` written into the
        preallocated C-contiguous float array ``out`` (no other array of that size is
        made); returns ``out``.  Its shape is ``(len(us), len(vs), 3)`` for positions and
        ``(len(us), len(vs), order+1, order+1, 3)`` for partials, laid out as
        :meth:`grid_derivatives` returns them.  Reusing one buffer across calls skips the
        page faults of a fresh array; values are not checked for finiteness.

        >>> import numpy as np, surfmod as sm
        >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
        >>> buf = np.empty((2, 3, 3))
        >>> sm.BSplineSurface(net, (3, 3)).grid_into([0, 1], [0, 0.5, 1], buf)[1, 1]
        array([3. , 1.5, 0. ])
        >>> ders = sm.BSplineSurface(net, (3, 3)).grid_into([0.5], [0.5], np.empty((1, 1, 2, 2, 3)), order=1)
        >>> ders[0, 0, 1, 0], ders[0, 0, 0, 1]
        (array([3., 0., 0.]), array([0., 3., 0.]))
        """
        order = checks.derivative_order(order)
        (u0, u1), (v0, v1) = self.domain
        us = checks.parameters(np.atleast_1d(us), "us", (u0, u1)).ravel()
        vs = checks.parameters(np.atleast_1d(vs), "vs", (v0, v1)).ravel()
        shape = (us.size, vs.size, 3) if order == 0 else (us.size, vs.size, order + 1, order + 1, 3)
        if not (isinstance(out, np.ndarray) and out.dtype == np.float64 and out.flags.c_contiguous
                and out.flags.writeable and out.shape == shape):
            raise SurfmodError(f"out: expected a writable C-contiguous float64 array of shape "
                               f"{shape}, got {getattr(out, 'shape', type(out).__name__)}")
        if us.size and vs.size:
            local.surface_grid(self._local_net(), us, vs, order, out=out)
        return out

    def geom(self):
        from ..occ.geom import bspline_surface

        return bspline_surface(self.control_points, self.degree, self.knots, self.weights)

    def transformed(self, matrix) -> "BSplineSurface":
        """Affine maps commute with (rational) B-splines: map the control points."""
        m = transforms.affine(matrix)
        return BSplineSurface._trusted(transforms.apply(m, self.control_points), self.degree, self.knots, self.weights)

    def to_bspline(self) -> "BSplineSurface":
        return self

    # -- knot algorithms -------------------------------------------------------------------
    def _along(self, direction: int, fn):
        """Run a knot routine along u (0) or v (1) on the homogeneous net."""
        h = self._homogeneous if direction == 0 else self._homogeneous.transpose(1, 0, 2)
        k, h2 = fn(self.knots[direction], self.degree[direction], h)
        if direction == 1:
            h2 = h2.transpose(1, 0, 2)
        knots = (k, self.knots[1]) if direction == 0 else (self.knots[0], k)
        return knots, h2

    def _rebuilt(self, knots, h):
        pts, w = cartesian(h, self.rational)
        return BSplineSurface._trusted(pts, self.degree, knots, w)

    def insert_knot(self, u: float | None = None, v: float | None = None, times: int = 1) -> "BSplineSurface":
        """The same surface with ``u`` and/or ``v`` inserted ``times`` times."""
        times = checks.count(times, "times")
        out = self
        for direction, (name, value) in enumerate((("u", u), ("v", v))):
            if value is None:
                continue
            t = float(checks.parameters(value, name, self.domain[direction]))
            if kn.multiplicity(out.knots[direction], t) + times > out.degree[direction]:
                raise SurfmodError(f"times: multiplicity of {name}={t:g} would exceed the degree")
            knots, h = out._along(direction, lambda k, p, c: kn.insert_knot(k, p, c, t, times))
            out = out._rebuilt(knots, h)
        return out

    def segment(self, u_range=None, v_range=None) -> "BSplineSurface":
        """The exact sub-patch over ``u_range x v_range`` (each defaults to the full range),
        equal to OCCT's ``Geom_BSplineSurface::Segment``."""
        out = self
        for direction, (name, rng) in enumerate((("u_range", u_range), ("v_range", v_range))):
            if rng is None:
                continue
            a, b = _ordered_range(rng, name, self.domain[direction])
            knots, h = out._along(direction, lambda k, p, c: kn.segment(k, p, c, a, b))
            out = out._rebuilt(knots, h)
        return out

    def split(self, u: float | None = None, v: float | None = None) -> list["BSplineSurface"]:
        """Split at ``u`` and/or ``v`` into 2 or 4 exact pieces (u-major order)."""
        (u0, u1), (v0, v1) = self.domain
        u, v = (None if t is None else _interior(t, name, rng) for t, name, rng in ((u, "u", (u0, u1)), (v, "v", (v0, v1))))
        us = [(u0, u1)] if u is None else [(u0, float(u)), (float(u), u1)]
        vs = [(v0, v1)] if v is None else [(v0, float(v)), (float(v), v1)]
        return [self.segment(ur, vr) for ur in us for vr in vs]

    def isocurve(self, u: float | None = None, v: float | None = None) -> BSplineCurve:
        """The exact iso-parametric curve at constant ``u`` (a curve in v) or constant ``v``."""
        if (u is None) == (v is None):
            raise SurfmodError("isocurve: give exactly one of u or v")
        direction = 0 if u is not None else 1
        value = u if u is not None else v
        t = checks.parameters(np.atleast_1d(float(value)), "u" if u is not None else "v", self.domain[direction])
        n_ctrl = self.control_points.shape[direction]
        b = basis_matrix(self.knots[direction], self.degree[direction], n_ctrl, t)[0, 0]
        h = np.tensordot(b, self._homogeneous, axes=(0, direction))
        pts, w = cartesian(h, self.rational)
        other = 1 - direction
        return BSplineCurve._trusted(pts, self.degree[other], self.knots[other], w)


def _interior(value, name, domain):
    """A single parameter strictly inside ``domain`` (a split position)."""
    t = checks.parameters(value, name, domain)
    if t.size != 1:
        raise SurfmodError(f"{name}: expected one split parameter, got shape {t.shape}")
    t = float(t.item())
    if not domain[0] < t < domain[1]:
        raise SurfmodError(f"{name}: split parameter {t:g} must lie strictly inside ({domain[0]:g}, {domain[1]:g})")
    return t


def _pair(value, name):
    try:
        a, b = value
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected a pair (u, v), got {value!r}") from None
    return a, b
