"""The superellipsoid (Barr's superquadric) and its bicubic B-spline fit with a stated
tolerance (:func:`superellipsoid`), its signed-power parametric and implicit forms.
See :doc:`/guide/surfaces` (section "The superellipsoid and the three forms").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..eval.basis import basis_matrix
from ..nets.knots import span_samples
from .fitting import FittedSurface, averaging_knots, interpolate
from .forms import ImplicitSurface

_TABLE = 4001  # samples of the quadrant table behind the angle redistribution
_MAX_SAMPLES = 801


def signed_power(base: np.ndarray, exponent: float) -> np.ndarray:
    """``sgn(base) |base|^exponent`` (the superquadric's signed power), vectorized.

    >>> signed_power(np.array([-8.0, 0.0, 8.0]), 1 / 3)
    array([-2.,  0.,  2.])
    """
    return np.sign(base) * np.abs(base) ** exponent


def _quadrant_table(s: float):
    """``(W, τ, a)``: a monotone table mapping a normalized weight ``W`` in [0, 1] to the
    table variable ``τ`` of the angle ``φ = _crowded(τ, a)`` in [0, π/2] on one quadrant
    of the superellipse ``(cos^s φ, sin^s φ)``.

    For ``s >= 1`` the map is the identity; for ``s < 1`` the weight is the arc length
    weighted by ``(1 + κ²)^(3/8)`` (``~ κ^(3/4)`` at sharp edges: equidistributes the
    cubic interpolation error ``~ h^4 κ^3``; smooth where the curvature vanishes)."""
    tau = np.linspace(0.0, 1.0, _TABLE)
    if s >= 1.0:
        return tau, tau, 1.0
    a = 1.0 / s
    c, sn = _crowded_cos_sin(tau, a)
    pts = np.stack([c**s, sn**s], axis=-1)
    seg = np.diff(pts, axis=0)
    ds = np.linalg.norm(seg, axis=-1)
    ang = np.arctan2(seg[:, 1], seg[:, 0])
    dpsi = np.zeros_like(ds)
    dpsi[1:] = 0.5 * np.abs(np.diff(ang))
    dpsi[:-1] += 0.5 * np.abs(np.diff(ang))
    # ds (1 + κ²)^(3/8) with κ = dψ/ds, written without the division
    w = (ds**2 + dpsi**2) ** 0.375 * ds**0.25
    cum = np.concatenate([[0.0], np.cumsum(w)])
    cum /= cum[-1]
    keep = np.concatenate([[True], np.diff(cum) > 0])
    return cum[keep], tau[keep], a


def _crowded_cos_sin(tau, a):
    """``(cos φ, sin φ)`` of ``φ = _crowded(τ, a)``, the cosine taken as the sine of the
    complementary angle so that both stay accurate near 0 and π/2."""
    return np.sin(_crowded(1.0 - tau, a)), np.sin(_crowded(tau, a))


def _crowded(tau, a):
    """``φ = (π/2) τ^a / (τ^a + (1-τ)^a)``: a smooth angle table that crowds where the
    signed power ``^s`` (a = 1/s) is steep, at both ends of the quadrant."""
    if a == 1.0:
        return tau * (np.pi / 2)
    return (np.pi / 2) * tau**a / (tau**a + (1.0 - tau) ** a)


class _AngleMap:
    """Vectorized map ``t in [0, 1] -> θ`` over ``quarters`` quadrants starting at ``θ0``,
    each quadrant by the (mirror-symmetric) quadrant table."""

    def __init__(self, s: float, theta0: float, quarters: int):
        self.table = _quadrant_table(s)
        self.theta0, self.quarters = theta0, quarters

    def _parts(self, t):
        w, tau, a = self.table
        x = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * self.quarters
        k = np.clip(np.floor(x), 0, self.quarters - 1)
        f = x - k
        # quadrants alternate between leaving an axis where |cos| = 1 and arriving at
        # one: the signed powers are mirror-symmetric about every multiple of π/2
        start = self.theta0 + k * (np.pi / 2)
        rising = _starts_on_x_axis(start)
        # interpolate the smooth table variable τ, then map it to the angle exactly
        tau_f = np.where(rising, np.interp(f, w, tau), np.interp(1.0 - f, w, tau))
        return start, rising, tau_f, a

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """The angle θ (for display; use :meth:`cos_sin` for evaluation)."""
        start, rising, tau_f, a = self._parts(t)
        phi = _crowded(tau_f, a)
        return start + np.where(rising, phi, np.pi / 2 - phi)

    def cos_sin(self, t: np.ndarray):
        """``(cos θ, sin θ)`` computed from the local angle, so that angles within
        1e-20 of a multiple of π/2 (sharp cases) keep their precision."""
        start, _rising, tau_f, a = self._parts(t)
        mid = start + np.pi / 4
        c, s = _crowded_cos_sin(tau_f, a)
        # φ is measured from the axis where |cos| = 1 in both kinds of quadrant
        return np.sign(np.cos(mid)) * c, np.sign(np.sin(mid)) * s


def _starts_on_x_axis(start: np.ndarray) -> np.ndarray:
    """True where the quadrant starts at an even multiple of π/2 (cos = ±1 end), so the
    quadrant table (which starts at φ = 0, cos = 1) applies unmirrored."""
    k = np.rint(start / (np.pi / 2)).astype(int)
    return (k % 2) == 0


class Superellipsoid(FittedSurface):
    """A superellipsoid fitted by a bicubic B-spline (see :doc:`/guide/surfaces` (section
    "The superellipsoid and the three forms")).

    Attributes: ``rx, ry, rz, s1, s2``, ``tolerance`` (requested), ``max_deviation``
    (measured largest distance between the spline and the analytic surface at the same
    parameters, an upper bound of the geometric distance), ``samples`` (grid size).
    Methods: :meth:`parametric` (analytic points at angles), :meth:`analytic_points`
    (analytic points at the spline's ``(u, v)``), :meth:`implicit` (F at points) and
    :meth:`implicit_surface` (an :class:`~surfmod.construct.forms.ImplicitSurface`).

    >>> import surfmod as sm
    >>> s = sm.superellipsoid(1, 1, 1, 0.5, 0.5)
    >>> s.parametric(0.0, 0.0).tolist(), float(s.implicit((1.0, 0.0, 0.0)))
    ([1.0, 0.0, 0.0], 0.0)
    """

    occt_construct = "Geom_BSplineSurface (bicubic fit of the superellipsoid)"

    # -- analytic forms --------------------------------------------------------------------
    def parametric(self, eta, omega) -> np.ndarray:
        """Analytic points at latitude ``eta`` and longitude ``omega`` (radians)."""
        return superellipsoid_points(self.rx, self.ry, self.rz, self.s1, self.s2, eta, omega)

    def angles(self, u, v):
        """The angles ``(η, ω)`` that the spline parameters ``(u, v)`` stand for."""
        return self._eta_map(np.asarray(u, dtype=float)), self._omega_map(np.asarray(v, dtype=float))

    def analytic_points(self, u, v) -> np.ndarray:
        """Analytic points at the spline's parameters (what the spline approximates)."""
        ecs = self._eta_map.cos_sin(np.asarray(u, dtype=float))
        wcs = self._omega_map.cos_sin(np.asarray(v, dtype=float))
        return _points_cs(self.rx, self.ry, self.rz, self.s1, self.s2, ecs, wcs)

    def implicit(self, xyz) -> np.ndarray:
        """``F(x, y, z)`` of the implicit form at points ``(..., 3)``; 0 on the surface."""
        p = np.asarray(xyz, dtype=float)
        return superellipsoid_implicit(self.rx, self.ry, self.rz, self.s1, self.s2, p[..., 0], p[..., 1], p[..., 2])

    def implicit_surface(self):
        """The implicit form as an :class:`~surfmod.construct.forms.ImplicitSurface`."""
        rx, ry, rz, s1, s2 = self.rx, self.ry, self.rz, self.s1, self.s2
        r = max(rx, ry, rz)
        return ImplicitSurface(
            lambda x, y, z: superellipsoid_implicit(rx, ry, rz, s1, s2, x, y, z),
            bounds=((-rx, rx), (-ry, ry), (-rz, rz)),
            step=1e-6 * r,
        )

    def deviation(self, per_span: int = 4) -> float:
        """Max ``|spline(u, v) - analytic(u, v)|`` on a grid with ``per_span`` points per
        knot span in each direction (measured again, not cached)."""
        return _deviation(self, checks.count(per_span, "per_span", minimum=1))


def superellipsoid_points(rx, ry, rz, s1, s2, eta, omega) -> np.ndarray:
    """Analytic superellipsoid points (broadcasting ``eta``, ``omega``)."""
    eta, omega = np.asarray(eta, dtype=float), np.asarray(omega, dtype=float)
    return _points_cs(rx, ry, rz, s1, s2, (np.cos(eta), np.sin(eta)), (np.cos(omega), np.sin(omega)))


def _points_cs(rx, ry, rz, s1, s2, eta_cs, omega_cs) -> np.ndarray:
    """Points from ``(cos η, sin η)`` and ``(cos ω, sin ω)`` (broadcasting)."""
    ce, se = signed_power(eta_cs[0], s1), signed_power(eta_cs[1], s1)
    cw, sw = signed_power(omega_cs[0], s2), signed_power(omega_cs[1], s2)
    ce, se, cw, sw = np.broadcast_arrays(ce, se, cw, sw)
    return np.stack([rx * ce * cw, ry * ce * sw, rz * se], axis=-1)


def superellipsoid_implicit(rx, ry, rz, s1, s2, x, y, z) -> np.ndarray:
    """``(|x/rx|^(2/s2) + |y/ry|^(2/s2))^(s2/s1) + |z/rz|^(2/s1) - 1``."""
    a = np.abs(np.asarray(x, dtype=float) / rx) ** (2.0 / s2) + np.abs(np.asarray(y, dtype=float) / ry) ** (2.0 / s2)
    return a ** (s2 / s1) + np.abs(np.asarray(z, dtype=float) / rz) ** (2.0 / s1) - 1.0


def _deviation(s, per_span):
    # at the knots and also between data parameters (the knots of an interpolant sit between them)
    uu, vv = (np.unique(np.concatenate([span_samples(np.unique(s.knots[k]), per_span),
                                        span_samples(s.parameters[k], per_span)])) for k in (0, 1))
    fitted = s.grid(uu, vv)
    exact = s.analytic_points(uu[:, None], vv[None, :])
    return float(np.linalg.norm(fitted - exact, axis=-1).max())


def _curve_error(angle_map, s, count, radius):
    """1-D check: cubic interpolation of the superellipse through ``count`` samples;
    max error at 3 points per span (scaled by ``radius``)."""
    t = np.linspace(0.0, 1.0, count)
    c, sn = angle_map.cos_sin(t)
    pts = np.stack([signed_power(c, s), signed_power(sn, s)], axis=-1)
    knots = averaging_knots(t, 3)

    ctrl = np.linalg.solve(basis_matrix(knots, 3, count, t)[0], pts)
    tc = np.linspace(0.0, 1.0, 3 * (count - 1) + 1)
    fitted = basis_matrix(knots, 3, count, tc)[0] @ ctrl
    c, sn = angle_map.cos_sin(tc)
    exact = np.stack([signed_power(c, s), signed_power(sn, s)], axis=-1)
    return float(np.linalg.norm(fitted - exact, axis=-1).max()) * radius


def _count_for(angle_map, s, radius, tol, start):
    """``(n, error)``: the samples of one direction whose cubic interpolant meets ``tol``
    (at most about 15 trials, growing by half each), or ``_MAX_SAMPLES`` and the error
    they leave."""
    n = start
    while True:
        error = _curve_error(angle_map, s, n, radius)
        if error <= tol or n >= _MAX_SAMPLES:
            return n, error
        n = min(_MAX_SAMPLES, int(n * 1.5) + 1)


#: the deviation check samples about 4.4 points per data point and direction (knots and
#: parameters, 4 per span); 5 x 5 per sample bounds its grid before any fit is made
_CHECK_POINTS_PER_SAMPLE = 25


def superellipsoid(rx, ry, rz, s1, s2, *, tolerance: float | None = None) -> Superellipsoid:
    """A superellipsoid as a bicubic B-spline within ``tolerance`` of the analytic surface.

    ``tolerance`` defaults to ``1e-3 * max(rx, ry, rz)``; the measured deviation is in
    ``max_deviation``.  Exponents must lie in ``[0.05, 5]``.

    >>> import surfmod as sm
    >>> s = sm.superellipsoid(2, 1.5, 1, 0.5, 0.5)
    >>> s.max_deviation <= s.tolerance
    True
    >>> e = sm.superellipsoid(2, 1.5, 1, 1, 1)      # the ellipsoid
    >>> import numpy as np; p = e.points(0.3, 0.7)
    >>> bool(abs((p[0] / 2) ** 2 + (p[1] / 1.5) ** 2 + p[2] ** 2 - 1) < 2e-3)
    True
    """
    rx, ry, rz = (checks.positive(r, name) for r, name in ((rx, "rx"), (ry, "ry"), (rz, "rz")))
    s1, s2 = checks.positive(s1, "s1"), checks.positive(s2, "s2")
    for value, name in ((s1, "s1"), (s2, "s2")):
        if not 0.05 <= value <= 5.0:
            raise SurfmodError(f"{name}: exponent must lie in [0.05, 5], got {value:g}")
    size = max(rx, ry, rz)
    tol = 1e-3 * size if tolerance is None else checks.tolerance(tolerance, "tolerance", size)
    if tol < 1e-7 * size:
        raise SurfmodError(f"tolerance: {tol:g} is below what a fitted bicubic can reach (1e-7 x size)")
    eta_map = _AngleMap(s1, -np.pi / 2, 2)
    omega_map = _AngleMap(s2, -np.pi, 4)
    # each direction to a share of the tolerance, then refine both until the surface meets it
    (n_u, err_u), (n_v, err_v) = _count_for(eta_map, s1, size, tol / 3, 9), _count_for(omega_map, s2, size, tol / 3, 13)
    # a profile the finest samples leave off by more than four times the tolerance: so is the
    # surface (the profile's error, scaled by the largest radius, overstates it by up to ~1.5x)
    if max(err_u, err_v) > 4 * tol:
        raise SurfmodError(f"tolerance: {tol:g} needs more than {_MAX_SAMPLES} samples along "
                           f"{'eta (s1)' if err_u > tol else 'omega (s2)'} (reached {max(err_u, err_v):.3g}); "
                           "use a larger tolerance")
    while True:
        if _CHECK_POINTS_PER_SAMPLE * n_u * n_v > checks.MAX_POINTS:
            raise SurfmodError(f"tolerance: {tol:g} needs a fit of more than {n_u} x {n_v} samples, whose "
                               f"check would exceed {checks.MAX_POINTS:,} points; use a larger tolerance")
        us, vs = np.linspace(0.0, 1.0, n_u), np.linspace(0.0, 1.0, n_v)
        ecs, wcs = eta_map.cos_sin(us[:, None]), omega_map.cos_sin(vs[None, :])
        pts = _points_cs(rx, ry, rz, s1, s2, ecs, wcs)
        fit = interpolate(pts, (3, 3), parameters=(us, vs))
        # the fit's residual at its samples gives way to the measured deviation below
        fields = {k: v for k, v in fit.__dict__.items() if k != "max_deviation"}
        fields.update(tolerance_requested=tol, samples=(n_u, n_v))
        obj = Superellipsoid._construct_fast(
            **fields, rx=rx, ry=ry, rz=rz, s1=s1, s2=s2, _eta_map=eta_map, _omega_map=omega_map
        )
        obj.max_deviation = _deviation(obj, 4)
        if obj.max_deviation <= tol:
            return obj
        if n_u >= _MAX_SAMPLES and n_v >= _MAX_SAMPLES:
            raise SurfmodError(
                f"tolerance: could not fit within {tol:g} (reached {obj.max_deviation:g} with {n_u} x {n_v} samples)"
            )
        n_u, n_v = min(_MAX_SAMPLES, int(n_u * 1.3) + 1), min(_MAX_SAMPLES, int(n_v * 1.3) + 1)
