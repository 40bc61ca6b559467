"""Interpolation (:func:`interpolate`) and approximation (:func:`approximate`) surfaces through
an (n, m, 3) grid of points, both a :class:`FittedSurface` with its data parameters and
measured ``max_deviation``.  Its OCCT twin (``GeomAPI_PointsToBSplineSurface``) is
:mod:`surfmod.occ.points_to_bspline`, behind the kernel door.
See :doc:`/guide/surfaces` (section "Fitting a grid of points").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..eval.basis import basis_matrix
from ..nets.bspline import BSplineSurface

METHODS = ("chord", "centripetal", "uniform")


class FittedSurface(BSplineSurface):
    """A B-spline surface fitted to a grid of points.

    Extra attributes: ``data`` (the ``(n, m, 3)`` points), ``parameters`` (``(us, vs)``
    at which the data are matched), ``max_deviation`` (largest ``|S(u_k, v_l) - Q_kl|``),
    ``tolerance`` (the requested bound for approximations, ``None`` for interpolation)
    and ``kind`` (``"interpolation"`` or ``"approximation"``).

    >>> import numpy as np, surfmod as sm
    >>> x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    >>> s = sm.interpolate(np.stack([x, y, x * y], axis=-1))
    >>> s.kind, [p.tolist() for p in s.parameters][0]
    ('interpolation', [0.0, 0.3333333333333333, 0.6666666666666666, 1.0])
    """

    occt_construct = "Geom_BSplineSurface (fitted; cf. GeomAPI_PointsToBSplineSurface)"

    @classmethod
    def _make(cls, net, degree, knots, data, params, kind, tolerance=None):
        obj = cls._trusted(net, degree, knots, None)
        obj.data = checks.frozen(data)
        obj.parameters = (checks.frozen(params[0]), checks.frozen(params[1]))
        obj.kind = kind
        obj.tolerance_requested = tolerance
        fitted = obj._grid_derivatives(obj.parameters[0], obj.parameters[1], 0)[:, :, 0, 0]
        obj.max_deviation = float(np.linalg.norm(fitted - data, axis=-1).max())
        return obj

    @property
    def tolerance(self):
        """The requested tolerance (approximation) or ``None`` (interpolation)."""
        return self.tolerance_requested

    def occt_fit(self, tolerance: float | None = None):
        """OCCT's fit of the same data and the distance of the data points to it.

        Interpolation uses ``GeomAPI_PointsToBSplineSurface.Interpolate`` (bicubic,
        chord length); approximation uses ``Init`` with the same degree and
        ``tolerance`` (default: the one requested here).  Returns
        ``(geom, max_distance)`` where ``max_distance`` is the largest distance from a
        data point to OCCT's surface (point projection).
        """
        from ..occ.points_to_bspline import points_to_bspline_surface
        from ..occ.sample import distances_to_surface

        tol = tolerance if tolerance is not None else (self.tolerance or 1e-6)
        geom = points_to_bspline_surface(
            self.data, self.degree, tol, interpolate=self.kind == "interpolation"
        )
        dist = distances_to_surface(geom, self.data.reshape(-1, 3), geom.Bounds())
        if np.any(np.isnan(dist)):
            from ..occ.topo import face_from_surface
            from ..occ.sample import distances_to_face

            miss = np.isnan(dist)
            dist[miss] = distances_to_face(face_from_surface(geom, *geom.Bounds()).wrapped, self.data.reshape(-1, 3)[miss])
        return geom, float(dist.max())


# -- parameters and knots -----------------------------------------------------------------
def grid_parameters(points: np.ndarray, axis: int, method: str) -> np.ndarray:
    """Parameters in ``[0, 1]`` along ``axis`` of an ``(n, m, 3)`` grid, averaged over the
    other axis (P&T eq. 9.5/9.6 and 9.15); rows of coincident points (poles) are skipped."""
    q = np.moveaxis(points, axis, 0)  # (n, k, 3)
    n = q.shape[0]
    if method == "uniform":
        return np.linspace(0.0, 1.0, n)
    d = np.linalg.norm(np.diff(q, axis=0), axis=-1)  # (n-1, k)
    if method == "centripetal":
        d = np.sqrt(d)
    total = d.sum(axis=0)
    scale = max(float(total.max()), 1e-300)
    ok = total > 1e-12 * scale
    if not np.any(ok):
        raise SurfmodError(f"points: all points coincide along axis {axis}, no parametrization exists")
    t = np.zeros((n, int(ok.sum())))
    t[1:] = np.cumsum(d[:, ok], axis=0) / total[ok]
    out = t.mean(axis=1)
    out[0], out[-1] = 0.0, 1.0
    if np.any(np.diff(out) <= 0):
        raise SurfmodError(f"points: consecutive points coincide along axis {axis}, parameters not increasing")
    return out


def averaging_knots(params: np.ndarray, degree: int) -> np.ndarray:
    """Knots by averaging (P&T eq. 9.8): clamped, interior knots are running means of
    ``degree`` consecutive parameters."""
    n, p = params.size, degree
    inner = np.array([params[j : j + p].mean() for j in range(1, n - p)])
    return np.concatenate([np.full(p + 1, params[0]), inner, np.full(p + 1, params[-1])])


def approximation_knots(params: np.ndarray, degree: int, n_ctrl: int) -> np.ndarray:
    """Knots for least squares with ``n_ctrl`` control points (P&T eq. 9.68/9.69), so
    every knot span holds at least one parameter (Schoenberg-Whitney)."""
    p, m1 = degree, params.size
    d = m1 / (n_ctrl - p)
    inner = []
    for j in range(1, n_ctrl - p):
        i = int(j * d)
        a = j * d - i
        inner.append((1.0 - a) * params[i - 1] + a * params[i])
    return np.concatenate([np.full(p + 1, params[0]), inner, np.full(p + 1, params[-1])])


def interp_along(params, knots, p, data):
    """Solve ``B c = data`` along axis 0 for every trailing column at once.

    With knots by averaging, ``B`` is banded (at most ``p`` sub- and super-diagonals,
    P&T 9.2.1), so one banded LU (``scipy.linalg.solve_banded``) serves all columns."""
    from scipy.linalg import solve_banded

    n = params.size
    b = basis_matrix(knots, p, n, params)[0]
    flat = data.reshape(n, -1)
    rows, cols = np.nonzero(b)
    lower = int(max(0, (rows - cols).max())) if rows.size else 0
    upper = int(max(0, (cols - rows).max())) if rows.size else 0
    ab = np.zeros((lower + upper + 1, n))
    ab[upper + rows - cols, cols] = b[rows, cols]
    try:
        with np.errstate(all="raise"):
            sol = solve_banded((lower, upper), ab, flat)
    except (np.linalg.LinAlgError, FloatingPointError, ValueError):
        raise SurfmodError("points: the interpolation system is singular (repeated parameters)") from None
    return sol.reshape(data.shape)


def _lsq_along(params, knots, p, n_ctrl, data):
    """Least-squares fit along axis 0 with ``n_ctrl`` control points, all columns at once."""
    b = basis_matrix(knots, p, n_ctrl, params)[0]
    flat = data.reshape(params.size, -1)
    sol, *_ = np.linalg.lstsq(b, flat, rcond=None)
    return sol.reshape((n_ctrl,) + data.shape[1:]), b


# -- checks -------------------------------------------------------------------------------
def _check_grid(points, degree):
    q = checks.finite_array(points, "points", ndim=3, last=3)
    try:
        p, r = degree
    except (TypeError, ValueError):
        raise SurfmodError(f"degree: expected a pair (p, q), got {degree!r}") from None
    p = checks.count(p, "degree[0] (u)", minimum=1)
    r = checks.count(r, "degree[1] (v)", minimum=1)
    n, m = q.shape[:2]
    if n < p + 1:
        raise SurfmodError(f"points: degree {p} in u needs at least {p + 1} rows of points, got {n}")
    if m < r + 1:
        raise SurfmodError(f"points: degree {r} in v needs at least {r + 1} columns of points, got {m}")
    return q, p, r


def _check_method(method):
    if method not in METHODS:
        raise SurfmodError(f"method: expected one of {METHODS}, got {method!r}")
    return method


def _check_params(value, name, count):
    t = checks.finite_array(value, name, ndim=1)
    if t.size != count:
        raise SurfmodError(f"{name}: expected {count} parameters, got {t.size}")
    if np.any(np.diff(t) <= 0):
        raise SurfmodError(f"{name}: parameters must be strictly increasing")
    return t


def _parameters_for(q, method, parameters):
    if parameters is None:
        return grid_parameters(q, 0, method), grid_parameters(q, 1, method)
    try:
        pu, pv = parameters
    except (TypeError, ValueError):
        raise SurfmodError("parameters: expected a pair (us, vs)") from None
    return _check_params(pu, "parameters[0]", q.shape[0]), _check_params(pv, "parameters[1]", q.shape[1])


# -- public constructors ------------------------------------------------------------------
def interpolate(points, degree=(3, 3), method: str = "chord", parameters=None) -> FittedSurface:
    """The B-spline surface through every point of an ``(n, m, 3)`` grid.

    Global interpolation (P&T 9.2.5): ``method`` ``"chord"`` (chord length),
    ``"centripetal"`` or ``"uniform"`` parameters averaged over rows and columns, or
    explicit ``parameters=(us, vs)``; knots by averaging; the control net solves one
    linear system per direction.  ``max_deviation`` is the residual at the data points
    (round-off only).

    >>> import numpy as np, surfmod as sm
    >>> x, y = np.meshgrid(np.linspace(0, 3, 5), np.linspace(0, 2, 4), indexing="ij")
    >>> pts = np.stack([x, y, np.sin(x) * np.cos(y)], axis=-1)
    >>> s = sm.interpolate(pts, degree=(3, 3))
    >>> s.control_points.shape, bool(s.max_deviation < 1e-12)
    ((5, 4, 3), True)
    """
    q, p, r = _check_grid(points, degree)
    _check_method(method)
    us, vs = _parameters_for(q, method, parameters)
    ku, kv = averaging_knots(us, p), averaging_knots(vs, r)
    tmp = interp_along(us, ku, p, q)  # (n, m, 3): control rows in u
    net = interp_along(vs, kv, r, tmp.transpose(1, 0, 2)).transpose(1, 0, 2)
    return FittedSurface._make(net, (p, r), (ku, kv), q, (us, vs), "interpolation")


def _fit_count(params, p, data, tol):
    """Smallest control count along axis 0 whose 1-D least-squares fit of every column
    stays within ``tol`` (binary search; the error falls with the count)."""
    n = params.size

    def error(k):
        if k >= n:
            return 0.0
        knots = approximation_knots(params, p, k)
        ctrl, b = _lsq_along(params, knots, p, k, data)
        fitted = np.tensordot(b, ctrl, axes=(1, 0))
        return float(np.linalg.norm(fitted - data, axis=-1).max())

    lo, hi = p + 1, n
    if error(lo) <= tol:
        return lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if error(mid) <= tol:
            hi = mid
        else:
            lo = mid
    return hi


def _lsq_surface(q, p, r, us, vs, nu, nv):
    n, m = q.shape[:2]
    ku = averaging_knots(us, p) if nu >= n else approximation_knots(us, p, nu)
    kv = averaging_knots(vs, r) if nv >= m else approximation_knots(vs, r, nv)
    tmp, _ = _lsq_along(us, ku, p, min(nu, n), q)
    net, _ = _lsq_along(vs, kv, r, min(nv, m), tmp.transpose(1, 0, 2))
    return net.transpose(1, 0, 2), (ku, kv)


def approximate(points, degree=(3, 3), tolerance: float | None = None, *, n_ctrl=None,
                method: str = "chord", parameters=None) -> FittedSurface:
    """A least-squares B-spline surface with fewer control points than data points.

    ``tolerance`` (default ``1e-3`` times the diagonal of the points' bounding box)
    bounds the max error ``|S(u_k, v_l) - Q_kl|`` at the data parameters; the number of
    control points per direction is the smallest that meets it (or fixed by
    ``n_ctrl=(nu, nv)``, then ``max_deviation`` is simply reported).  Knots follow P&T
    eq. 9.69 so each span holds data.

    >>> import numpy as np, surfmod as sm
    >>> x, y = np.meshgrid(np.linspace(0, 3, 30), np.linspace(0, 2, 20), indexing="ij")
    >>> pts = np.stack([x, y, np.sin(x) * np.cos(y)], axis=-1)
    >>> s = sm.approximate(pts, tolerance=1e-3)
    >>> bool(s.max_deviation <= 1e-3), s.control_points.shape[0] < 30
    (True, True)
    """
    q, p, r = _check_grid(points, degree)
    _check_method(method)
    us, vs = _parameters_for(q, method, parameters)
    n, m = q.shape[:2]
    diag = float(np.linalg.norm(q.reshape(-1, 3).max(axis=0) - q.reshape(-1, 3).min(axis=0)))
    tol = 1e-3 * max(diag, 1e-300) if tolerance is None else checks.tolerance(tolerance, "tolerance", diag)
    if n_ctrl is not None:
        try:
            nu, nv = n_ctrl
        except (TypeError, ValueError):
            raise SurfmodError(f"n_ctrl: expected a pair (nu, nv), got {n_ctrl!r}") from None
        nu = checks.count(nu, "n_ctrl[0]", minimum=p + 1)
        nv = checks.count(nv, "n_ctrl[1]", minimum=r + 1)
        if nu > n or nv > m:
            raise SurfmodError(f"n_ctrl: at most the data size ({n}, {m}) control points, got ({nu}, {nv})")
        net, knots = _lsq_surface(q, p, r, us, vs, nu, nv)
        return FittedSurface._make(net, (p, r), knots, q, (us, vs), "approximation", tol)
    # each direction to half the tolerance, then grow both until the surface meets it
    nu = _fit_count(us, p, q, tol / 2)
    nv = _fit_count(vs, r, q.transpose(1, 0, 2), tol / 2)
    while True:
        net, knots = _lsq_surface(q, p, r, us, vs, nu, nv)
        fit = FittedSurface._make(net, (p, r), knots, q, (us, vs), "approximation", tol)
        if fit.max_deviation <= tol or (nu >= n and nv >= m):
            return fit
        nu = min(n, max(nu + 1, int(nu * 1.25)))
        nv = min(m, max(nv + 1, int(nv * 1.25)))
