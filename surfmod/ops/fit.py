"""A B-spline surface through unordered points (a scan) with a guaranteed deviation
(:func:`fit`): parameters by projection onto a base surface, penalized least squares with
the thin-plate energy, knot spans halved until every point is within the tolerance, the
final distances measured by OCCT.  See :doc:`/guide/surfaces` (section "Fitting scattered
points").
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..eval.basis import basis_derivatives, find_spans
from ..nets.bspline import BSplineSurface
from ..nets.knots import greville
from .closest import newton_closest
from .project import project
from ..surface import require_surface

#: points per chunk when assembling the normal equations (memory bound)
CHUNK = 200_000
#: a local normal this close to perpendicular to the base normal (|cos| below, 84 deg)
#: marks a place where a height field over the base plane folds; more than
#: STEEP_FRACTION of such points and the plane is refused as a base
STEEP_COSINE = 0.1
STEEP_FRACTION = 0.01


class Fit(NamedTuple):
    """The result of :func:`fit`.

    ``surface`` (a ``BSplineSurface`` on ``[0, 1]^2``), ``max_deviation`` and ``rms``
    (distances of the points to the surface, measured by OCCT projection),
    ``distances`` (per point), ``parameters`` (``(u, v)`` foot points), ``converged``
    (every distance within ``tolerance``), ``tolerance``, ``iterations``, ``smoothing``.

    >>> import numpy as np, surfmod as sm
    >>> rng = np.random.default_rng(0)
    >>> xy = rng.random((400, 2)); pts = np.column_stack([xy, 0.2 * xy[:, 0] * xy[:, 1]])
    >>> f = sm.fit(pts, 1e-6)
    >>> f.converged, bool(f.max_deviation <= 1e-6), f.surface.degree
    (True, True, (3, 3))
    """

    surface: BSplineSurface
    max_deviation: float
    rms: float
    distances: np.ndarray
    parameters: tuple
    converged: bool
    tolerance: float
    iterations: int
    smoothing: float


# -- parametrization ------------------------------------------------------------------------
def pca_frame(points: np.ndarray):
    """Centroid and principal axes (rows, by decreasing variance) of the points."""
    c = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - c, full_matrices=False)
    return c, vt


def _unit(values, name):
    lo, hi = values.min(), values.max()
    if not hi - lo > 0:
        raise SurfmodError(f"{name}: the points do not spread in both directions of the base surface")
    return (values - lo) / (hi - lo)


def mean_normal_frame(points: np.ndarray, sample: int = 20_000, neighbours: int = 12, seed: int = 0):
    """The base plane: centroid, in-plane axes and normal (rows of a 3x3 matrix).

    The normal is the mean of local normals (smallest principal axis of each point's
    ``neighbours`` nearest points, on a random subset of ``sample`` points, oriented
    like the global PCA normal).  For a curved height field such as ``z = sin(2x)`` the
    global PCA plane tilts with the trend and folds the projection; the mean normal
    stays along the height direction.  The in-plane axes are the principal axes of the
    points projected onto that plane.  Also returned: the fraction of local normals
    nearly perpendicular to the plane's (where a height field over it would fold).
    """
    from scipy.spatial import cKDTree

    c, axes = pca_frame(points)
    rng = np.random.default_rng(seed)
    sub = points if len(points) <= sample else points[rng.choice(len(points), sample, replace=False)]
    k = min(neighbours, len(sub))
    _, idx = cKDTree(sub).query(sub, k=k)
    local = sub[idx] - sub[idx].mean(axis=1, keepdims=True)  # (M, k, 3)
    _, vecs = np.linalg.eigh(np.einsum("mki,mkj->mij", local, local))
    normals = vecs[:, :, 0]  # eigenvector of the smallest eigenvalue
    normals *= np.sign(normals @ axes[2])[:, None] + (normals @ axes[2] == 0)[:, None]
    n = normals.mean(axis=0)
    n = n / np.linalg.norm(n) if np.linalg.norm(n) > 1e-12 else axes[2]
    flat = (points - c) - np.outer((points - c) @ n, n)
    _, _, vt = np.linalg.svd(flat[:: max(1, len(flat) // sample)], full_matrices=False)
    e1 = vt[0] - (vt[0] @ n) * n
    e1 /= np.linalg.norm(e1)
    steep = float(np.mean(np.abs(normals @ n) < STEEP_COSINE))
    return c, np.array([e1, np.cross(n, e1), n]), steep


def base_parameters(points: np.ndarray, base):
    """Parameters in ``[0, 1]^2`` by projection onto ``base`` (a surfmod surface)."""
    base = require_surface(base, "base")
    pr = project(points, base)
    return _unit(pr.u, "base"), _unit(pr.v, "base")


class HeightFrame(NamedTuple):
    """The base plane of a height-field fit: ``origin + x e1 + y e2 + h n`` with
    ``x = x0 + u lx``, ``y = y0 + v ly``."""

    origin: np.ndarray
    axes: np.ndarray  # rows e1, e2, n
    x0: float
    lx: float
    y0: float
    ly: float

    def net(self, knots, degree, heights):
        """Control net whose in-plane coordinates are the linear map of the Greville
        abscissae (a B-spline reproduces linear functions exactly) and whose heights
        are ``heights`` ``(n, m)``."""
        gu, gv = (greville(k, p) for k, p in zip(knots, degree))
        x = self.x0 + gu * self.lx
        y = self.y0 + gv * self.ly
        e1, e2, nrm = self.axes
        return (self.origin + x[:, None, None] * e1 + y[None, :, None] * e2 + heights[..., None] * nrm)


def height_frame(points: np.ndarray):
    """The mean-normal plane of the points, their parameters on it and their heights."""
    c, axes, steep = mean_normal_frame(points)
    if steep > STEEP_FRACTION:
        raise SurfmodError(
            f"points: {100 * steep:.0f} % of the points lie where the surface stands nearly perpendicular "
            "to the points' mean plane, so they are no height field over it; give a base surface "
            "(base=...) that follows their shape"
        )
    local = (points - c) @ axes.T
    x, y, h = local[:, 0], local[:, 1], local[:, 2]
    u, v = _unit(x, "points"), _unit(y, "points")
    frame = HeightFrame(c, axes, float(x.min()), float(np.ptp(x)), float(y.min()), float(np.ptp(y)))
    return frame, u, v, h


# -- linear algebra ---------------------------------------------------------------------------
def _clamped_uniform(spans: int, degree: int) -> np.ndarray:
    return np.concatenate([np.zeros(degree), np.linspace(0.0, 1.0, spans + 1), np.ones(degree)])


def _local_basis(knots, degree, t):
    n = len(knots) - degree - 1
    spans = find_spans(knots, degree, n, t)
    return spans - degree, basis_derivatives(knots, degree, spans, t, 0)[:, 0, :]


def normal_equations(knots, degree, u, v, points):
    """``A^T A`` (sparse, ``nm x nm``) and ``A^T Q`` (``nm x 3``) of the collocation
    matrix ``A[k, i m + j] = N_i(u_k) M_j(v_k)``, assembled chunk by chunk."""
    from scipy import sparse

    (ku, kv), (p, q) = knots, degree
    n, m = len(ku) - p - 1, len(kv) - q - 1
    ata = sparse.csr_matrix((n * m, n * m))
    atq = np.zeros((n * m, points.shape[1]))
    for a in range(0, len(u), CHUNK):  # loop over memory chunks, not points
        uu, vv, qq = u[a : a + CHUNK], v[a : a + CHUNK], points[a : a + CHUNK]
        iu, bu = _local_basis(ku, p, uu)
        iv, bv = _local_basis(kv, q, vv)
        cols = ((iu[:, None] + np.arange(p + 1))[:, :, None] * m + (iv[:, None] + np.arange(q + 1))[:, None, :])
        vals = (bu[:, :, None] * bv[:, None, :]).reshape(len(uu), -1)
        rows = np.repeat(np.arange(len(uu), dtype=np.int32), (p + 1) * (q + 1))
        mat = sparse.csr_matrix((vals.ravel(), (rows, cols.reshape(-1).astype(np.int32))), shape=(len(uu), n * m))
        ata = ata + (mat.T @ mat)
        atq += mat.T @ qq
    return ata.tocsr(), atq


def gram_matrices(knots, degree):
    """``G[k][i, j] = integral N_i^(k) N_j^(k)`` for ``k = 0, 1, 2`` (Gauss-Legendre per
    knot span, exact for these polynomial integrands)."""
    n = len(knots) - degree - 1
    breaks = np.unique(knots[degree : n + 1])
    x, w = np.polynomial.legendre.leggauss(degree + 1)
    a, b = breaks[:-1, None], breaks[1:, None]
    t = ((b - a) * (x + 1) / 2 + a).ravel()
    wt = ((b - a) / 2 * w).ravel()
    spans = find_spans(knots, degree, n, t)
    ders = basis_derivatives(knots, degree, spans, t, min(2, degree))
    out = []
    for k in range(3):
        g = np.zeros((n, n))
        if k <= degree:
            vals = ders[:, k, :]  # (T, p+1)
            idx = spans[:, None] - degree + np.arange(degree + 1)
            contrib = wt[:, None, None] * vals[:, :, None] * vals[:, None, :]
            np.add.at(g, (idx[:, :, None], idx[:, None, :]), contrib)
        out.append(g)
    return out


def fairing_matrix(knots, degree):
    """The thin-plate energy as a sparse quadratic form on the flattened net (membrane
    energy in a direction of degree 1, where second derivatives vanish)."""
    from scipy import sparse

    gu, gv = gram_matrices(knots[0], degree[0]), gram_matrices(knots[1], degree[1])
    if min(degree) >= 2:
        terms = [(gu[2], gv[0], 1.0), (gu[1], gv[1], 2.0), (gu[0], gv[2], 1.0)]
    else:
        terms = [(gu[1], gv[0], 1.0), (gu[0], gv[1], 1.0)]
    k = sum(c * sparse.kron(sparse.csr_matrix(a), sparse.csr_matrix(b)) for a, b, c in terms)
    return k.tocsr()


def solve_net(knots, degree, u, v, points, smoothing):
    """Control net ``(n, m, d)`` of the penalized least-squares problem for data
    ``points`` ``(N, d)`` (3-D points, or heights with ``d = 1``)."""
    from scipy.sparse.linalg import spsolve

    (ku, kv), (p, q) = knots, degree
    n, m = len(ku) - p - 1, len(kv) - q - 1
    ata, atq = normal_equations(knots, degree, u, v, points)
    k = fairing_matrix(knots, degree)
    lam = smoothing * ata.diagonal().sum() / max(k.diagonal().sum(), 1e-300)
    # a vanishing multiple of the identity keeps poles that neither data nor energy
    # determine (possible only for degenerate inputs) at the origin of the system
    reg = 1e-14 * ata.diagonal().max()
    from scipy import sparse

    system = (ata + lam * k + reg * sparse.identity(n * m)).tocsc()
    sol = spsolve(system, atq)
    if not np.all(np.isfinite(sol)):
        raise SurfmodError("points: the least-squares system is singular (too few points for the poles)")
    return np.asarray(sol).reshape(n, m, points.shape[1])


# -- refinement -------------------------------------------------------------------------------
def refined(knots, degree, t, error, tol, limit):
    """Knots with every span holding a point of ``error > tol`` halved (at most up to
    ``limit`` poles); returns ``None`` when nothing may be inserted."""
    n = len(knots) - degree - 1
    breaks = np.unique(knots[degree : n + 1])
    piece = np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, len(breaks) - 2)
    worst = np.zeros(len(breaks) - 1)
    np.maximum.at(worst, piece, error)
    bad = np.nonzero(worst > tol)[0]
    room = limit - n
    if bad.size == 0 or room <= 0:
        return None
    if bad.size > room:  # the worst spans first
        bad = bad[np.argsort(worst[bad])[::-1][:room]]
    mids = 0.5 * (breaks[bad] + breaks[bad + 1])
    return np.sort(np.concatenate([knots, mids]))


def _check_max_poles(value, degree):
    if value is None:
        return (128, 128)
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        value = (value, value)
    try:
        a, b = value
    except (TypeError, ValueError):
        raise SurfmodError(f"max_poles: expected an integer or a pair (nu, nv), got {value!r}") from None
    return (checks.count(a, "max_poles[0]", minimum=degree[0] + 1),
            checks.count(b, "max_poles[1]", minimum=degree[1] + 1))


def _foot_points(surface, points, u, v):
    u, v = newton_closest(surface, points, u, v, iterations=8)
    d = np.linalg.norm(surface.points(u, v) - points, axis=-1)
    return u, v, d


def fit(points, tolerance: float, degree=(3, 3), *, smoothing: float = 1e-6, base=None,
        max_poles=None, initial_spans: int = 4, max_iterations: int = 30) -> Fit:
    """A B-spline surface within ``tolerance`` of unordered ``points`` ``(N, 3)``.

    ``degree`` ``(p, q)``; ``smoothing`` weights the thin-plate fairing (dimensionless,
    see :doc:`/guide/surfaces` (section "Fitting scattered points"); 0 disables it); ``base`` a surfmod surface whose
    parametrization seeds the parameters (default: the plane normal to the points' mean
    local normal, so the points should be a height field over some plane or be given a
    base); ``max_poles`` caps the
    poles per direction (an integer or ``(nu, nv)``, default 128).  The max and RMS
    distances are measured by OCCT projection of every point; ``converged`` says whether
    the tolerance was met before the pole limit.

    >>> import numpy as np, surfmod as sm
    >>> rng = np.random.default_rng(1)
    >>> xy = rng.uniform(-1, 1, (2000, 2))
    >>> pts = np.column_stack([xy, np.sin(2 * xy[:, 0]) * np.cos(xy[:, 1])])
    >>> f = sm.fit(pts, 1e-3)
    >>> bool(f.max_deviation <= 1e-3), max(f.surface.control_points.shape[:2]) <= 20
    (True, True)
    """
    q = checks.finite_array(points, "points", ndim=2, last=3)
    tol = checks.tolerance(tolerance, "tolerance", float(np.linalg.norm(np.ptp(q, axis=0))) if len(q) else 0.0)
    try:
        p_u, p_v = degree
    except (TypeError, ValueError):
        raise SurfmodError(f"degree: expected a pair (p, q), got {degree!r}") from None
    deg = (checks.count(p_u, "degree[0] (u)", minimum=1), checks.count(p_v, "degree[1] (v)", minimum=1))
    if smoothing is None or not np.isfinite(float(smoothing)) or float(smoothing) < 0:
        raise SurfmodError(f"smoothing: must be a finite number >= 0, got {smoothing!r}")
    smoothing = float(smoothing)
    limit = _check_max_poles(max_poles, deg)
    spans = checks.count(initial_spans, "initial_spans", minimum=1)
    need = (deg[0] + 1) * (deg[1] + 1)
    if q.shape[0] < need:
        raise SurfmodError(f"points: degree {deg} needs at least {need} points, got {q.shape[0]}")
    if base is None:  # height field over the mean-normal plane: only heights are unknown
        frame, u, v, heights = height_frame(q)
    else:
        frame, heights = None, None
        u, v = base_parameters(q, base)
    knots = [_clamped_uniform(min(spans, limit[d] - deg[d]), deg[d]) for d in (0, 1)]
    iterations = 0
    while True:
        iterations += 1
        if frame is not None:
            net = frame.net(knots, deg, solve_net(knots, deg, u, v, heights[:, None], smoothing)[..., 0])
        else:
            net = solve_net(knots, deg, u, v, q, smoothing)
        surface = BSplineSurface._trusted(net, deg, tuple(knots))
        fu, fv, dist = _foot_points(surface, q, u, v)
        if frame is None:  # parameter correction: the foot points are the new parameters
            u, v = fu, fv
        occt = False
        if dist.max() <= tol:
            from ..occ.points_to_bspline import project_points

            dist, _, _ = project_points(surface.geom(), q, fu, fv)
            occt = True
            if dist.max() <= tol:
                return _result(surface, dist, (fu, fv), True, tol, iterations, smoothing)
        if iterations >= max_iterations:
            break
        # refine where the points are far, located by their foot points on the surface
        new = [refined(knots[d], deg[d], (fu, fv)[d], dist, tol, limit[d]) for d in (0, 1)]
        if new[0] is None and new[1] is None:
            break
        knots = [k if nk is None else nk for k, nk in zip(knots, new)]
    if not occt:
        from ..occ.points_to_bspline import project_points

        dist, _, _ = project_points(surface.geom(), q, fu, fv)
    return _result(surface, dist, (fu, fv), bool(dist.max() <= tol), tol, iterations, smoothing)


def _result(surface, dist, params, converged, tol, iterations, smoothing):
    return Fit(surface, float(dist.max()), float(np.sqrt(np.mean(dist ** 2))), dist,
               (params[0], params[1]), converged, tol, iterations, smoothing)
