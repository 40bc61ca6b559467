"""Gordon surfaces (:func:`gordon`): one B-spline surface through a network of profile and
guide curves, the Boolean sum of two skins less the interpolant of their crossings.

A network whose curves do not cross at common parameters is reparametrized within half the
tolerance; the crossings themselves are hit exactly.
See :doc:`/guide/surfaces` (section "Gordon surfaces").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..nets.elevate import compatible, make_compatible, reparametrized
from .fitting import averaging_knots, interp_along
from .from_edge import as_curves

#: crossings closer than this (relative to the curve's parameter span) count as equal
SAME_PARAMETER = 1e-10


class GordonSurface(BSplineSurface):
    """A Gordon surface (:doc:`/guide/surfaces` (section "Gordon surfaces")); a B-spline
    surface that *is* its OCCT twin.  Attributes: ``profiles``, ``guides`` (the input curves,
    in network order), ``parameters`` (``(U, V)``: the guides' ``u`` and the profiles' ``v``),
    ``tolerance``, ``reparametrized`` (False when the network was used exactly).

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> net[1:3, 1:3, 2] = 1.0
    >>> base = sm.BSplineSurface(net, (3, 3))
    >>> profiles = [base.isocurve(v=t) for t in (0.0, 0.5, 1.0)]
    >>> guides = [base.isocurve(u=t) for t in (0.0, 0.3, 1.0)]
    >>> s = sm.gordon(profiles, guides, 1e-6)
    >>> bool(np.allclose(s.points(0.4, 0.5), base.points(0.4, 0.5)))
    True
    """

    occt_construct = "Geom_BSplineSurface (Gordon; cf. build123d Face.make_gordon_surface)"

    def network_deviation(self, samples: int = 64) -> float:
        """Largest distance from ``samples`` points on every network curve to this
        surface, measured by OCCT projection (``GeomAPI_ProjectPointOnSurf``)."""
        from ..occ.filling import curve_to_surface_distances

        (u0, u1), (v0, v1) = self.domain
        geom = self.geom()
        worst = 0.0
        for c in (*self.profiles, *self.guides):
            b = c.to_bspline()
            d = curve_to_surface_distances(geom, (u0, u1, v0, v1), b.geom(), samples)
            worst = max(worst, float(np.nanmax(d)))
        return worst

    def occt_gordon(self):
        """build123d's ``Face.make_gordon_surface`` on the same network (a ``Face``)."""
        from ..occ.filling import gordon_face

        return gordon_face([c.edge() for c in self.profiles], [c.edge() for c in self.guides], self.tolerance)


# -- crossings ------------------------------------------------------------------------------
def _crossings(profiles, guides, samples: int = 128, iterations: int = 30):
    """Parameters ``(u, v)`` ``(K, L)`` of the closest approach of each profile/guide pair
    and the gap there: dense sampling, then Gauss-Newton on all pairs at once."""
    tp = [np.linspace(*c.domain, samples) for c in profiles]
    tg = [np.linspace(*c.domain, samples) for c in guides]
    pp = np.stack([c.points(t) for c, t in zip(profiles, tp)])  # (K, S, 3)
    pg = np.stack([c.points(t) for c, t in zip(guides, tg)])  # (L, S, 3)
    d2 = np.sum((pp[:, None, :, None, :] - pg[None, :, None, :, :]) ** 2, axis=-1)  # (K, L, S, S)
    flat = d2.reshape(d2.shape[0], d2.shape[1], -1).argmin(axis=-1)
    ia, ib = np.unravel_index(flat, (samples, samples))
    k_idx, l_idx = np.meshgrid(np.arange(len(profiles)), np.arange(len(guides)), indexing="ij")
    u = np.array(tp)[k_idx, ia]
    v = np.array(tg)[l_idx, ib]
    for _ in range(iterations):  # loops over iterations and curves, not over points
        dp = np.empty(u.shape + (2, 3))
        dg = np.empty(v.shape + (2, 3))
        for i, c in enumerate(profiles):
            dp[i] = c.derivatives(u[i], 1)
        for j, c in enumerate(guides):
            dg[:, j] = c.derivatives(v[:, j], 1)
        r = dp[..., 0, :] - dg[..., 0, :]
        jac = np.stack([dp[..., 1, :], -dg[..., 1, :]], axis=-1)  # (K, L, 3, 2)
        jtj = np.einsum("...ki,...kj->...ij", jac, jac) + 1e-300 * np.eye(2)
        jtr = np.einsum("...ki,...k->...i", jac, r)
        step = -np.linalg.solve(jtj, jtr[..., None])[..., 0]
        u = np.clip(u + step[..., 0], [[c.domain[0]] for c in profiles], [[c.domain[1]] for c in profiles])
        v = np.clip(v + step[..., 1], [c.domain[0] for c in guides], [c.domain[1] for c in guides])
    gap = np.empty(u.shape)
    for i, c in enumerate(profiles):
        gap[i] = np.linalg.norm(c.points(u[i]) - np.stack([g.points(v[i, j]) for j, g in enumerate(guides)]), axis=-1)
    return u, v, gap


def _normalized(t, curves, axis):
    lo = np.array([c.domain[0] for c in curves])
    hi = np.array([c.domain[1] for c in curves])
    shape = (-1, 1) if axis == 0 else (1, -1)
    return (t - lo.reshape(shape)) / (hi - lo).reshape(shape)


def _reparametrized_curve(curve, crossings, targets, tolerance):
    """``curve(phi(t))`` as a cubic B-spline on ``[0, 1]`` with ``phi(targets) = crossings``
    (monotone piecewise cubic), interpolated at samples that include every target so the
    crossing points stay exact; refined until within ``tolerance`` of the curve."""
    from scipy.interpolate import CubicSpline, PchipInterpolator

    a, b = curve.domain
    x = np.concatenate([[0.0], targets, [1.0]])
    y = np.concatenate([[a], crossings, [b]])
    x, keep = np.unique(x, return_index=True)
    # a C2 map keeps curve(phi(t)) smooth, so its cubic interpolant converges fast; the
    # monotone (C1) PCHIP map is the fallback when the C2 one would turn back
    phi = CubicSpline(x, y[keep], bc_type="natural")
    if np.any(phi(np.linspace(0.0, 1.0, 2049), 1) <= 0):
        phi = PchipInterpolator(x, y[keep])
    per = 4
    while True:
        t = np.unique(np.concatenate([np.linspace(x0, x1, per + 1) for x0, x1 in zip(x[:-1], x[1:])]))
        pts = curve.points(np.clip(phi(t), a, b))
        deg = min(3, len(t) - 1)
        knots = averaging_knots(t, deg)
        ctrl = interp_along(t, knots, deg, pts)
        fitted = BSplineCurve._trusted(ctrl, deg, knots)
        mid = np.concatenate([np.linspace(x0, x1, 4 * per + 1) for x0, x1 in zip(x[:-1], x[1:])])
        err = float(np.linalg.norm(fitted.points(mid) - curve.points(np.clip(phi(mid), a, b)), axis=-1).max())
        if err <= tolerance or per >= 1024:
            if err > tolerance:
                raise SurfmodError(
                    f"tolerance: a network curve cannot be reparametrized within {tolerance:g} (reached {err:.3g})"
                )
            return fitted
        per = (3 * per + 1) // 2


# -- surface algebra ------------------------------------------------------------------------
def _compatible_sum(terms):
    """``sum(sign * surface)`` over ``(sign, net, (p, q), (U, V))`` after elevating every
    term to the common degrees and merging the knot vectors (exact)."""
    signs, nets = [t[0] for t in terms], [t[1] for t in terms]
    degree, knots = [], []
    for d in (0, 1):  # tol=0: snapping a knot would move its term, and the sum must be exact
        p, k, nets = compatible([(t[3][d], t[2][d], net) for t, net in zip(terms, nets)], tol=0.0, axis=d)
        degree.append(p)
        knots.append(k)
    return sum(sign * net for sign, net in zip(signs, nets)), tuple(degree), tuple(knots)


def _check_ends(curves, t, tn, tol, name, order, other):
    """Both ends of every curve must lie on the first / last curve of the other family."""
    for i, c in enumerate(curves):
        a, b = c.domain
        ends = c.points(np.array([a, b]))
        hits = c.points(np.array([t[i, 0], t[i, -1]]))
        gaps = np.linalg.norm(ends - hits, axis=-1)
        if gaps.max() > tol:
            which = ("first", "last")[int(gaps.argmax())]
            raise SurfmodError(
                f"{name}[{int(order[i])}]: its ends must lie on the first and last {other} "
                f"(the {which} one crosses it {gaps.max():.3g} from its end)"
            )


# -- public ---------------------------------------------------------------------------------
def _curves(value, name):
    return [c.to_bspline() for c in as_curves(value, name, "a Gordon surface")]


def gordon(profiles, guides, tolerance: float = 1e-4) -> GordonSurface:
    """The Gordon surface through a network of ``profiles`` (curves in ``u``) and
    ``guides`` (curves in ``v``), surfmod curves or build123d Edges/Wires.

    Every profile must cross every guide (within ``tolerance``); the order of the curves
    in each list does not matter, the network's order is found from the crossings.  Each
    network curve lies on the result within ``tolerance`` (exactly, to round-off, when the
    curves already cross at common parameters); ``network_deviation()`` measures it with
    OCCT.

    >>> import surfmod as sm
    >>> p = [sm.Line((0, y, 0), (3, y, 0)) for y in (0, 1, 2)]
    >>> g = [sm.Line((x, 0, 0), (x, 2, 0)) for x in (0, 1.5, 3)]
    >>> s = sm.gordon(p, g, 1e-6)
    >>> s.points(0.5, 0.5).round(12).tolist()
    [1.5, 1.0, 0.0]
    """
    tol = checks.positive(tolerance, "tolerance")
    prof = _curves(profiles, "profiles")
    guid = _curves(guides, "guides")
    net = np.concatenate([c.control_points.reshape(-1, c.control_points.shape[-1])[:, :3] for c in prof + guid])
    tol = checks.tolerance(tol, "tolerance", float(np.linalg.norm(np.ptp(net, axis=0))))
    u, v, gap = _crossings(prof, guid)
    if gap.max() > tol:
        i, j = np.unravel_index(int(gap.argmax()), gap.shape)
        raise SurfmodError(
            f"guides[{j}]: does not cross profiles[{i}] (closest approach {gap[i, j]:.3g} > tolerance {tol:g})"
        )
    un = _normalized(u, prof, 0)  # (K, L) in [0, 1] along each profile
    vn = _normalized(v, guid, 1)
    order_g = np.argsort(un.mean(axis=0))
    order_p = np.argsort(vn.mean(axis=1))
    prof = [prof[i] for i in order_p]
    guid = [guid[j] for j in order_g]
    u, v, un, vn = (a[np.ix_(order_p, order_g)] for a in (u, v, un, vn))
    for name, other, order, rows in (("profiles", "guides", order_p, un), ("guides", "profiles", order_g, vn.T)):
        for i, row in enumerate(rows):
            if np.any(np.diff(row) <= 0):
                raise SurfmodError(
                    f"{name}[{int(order[i])}]: crosses the {other} in a different order than the other {name}")
    _check_ends(prof, u, un, tol, "profiles", order_p, "guides")
    _check_ends(guid, v.T, vn.T, tol, "guides", order_g, "profiles")
    un[:, 0], un[:, -1], vn[0], vn[-1] = 0.0, 1.0, 0.0, 1.0
    u[:, 0], u[:, -1] = [c.domain[0] for c in prof], [c.domain[1] for c in prof]
    v[0], v[-1] = [c.domain[0] for c in guid], [c.domain[1] for c in guid]
    big_u, big_v = un.mean(axis=0), vn.mean(axis=1)
    exact = (np.abs(un - big_u).max() <= SAME_PARAMETER and np.abs(vn - big_v[:, None]).max() <= SAME_PARAMETER
             and not any(c.rational for c in (*prof, *guid)))
    if exact:
        p_curves = [reparametrized(c, 0.0, 1.0) for c in prof]
        g_curves = [reparametrized(c, 0.0, 1.0) for c in guid]
    else:
        p_curves = [_reparametrized_curve(c, u[i], big_u, tol / 2) for i, c in enumerate(prof)]
        g_curves = [_reparametrized_curve(c, v[:, j], big_v, tol / 2) for j, c in enumerate(guid)]
    p_curves = make_compatible(p_curves)
    g_curves = make_compatible(g_curves)
    k_p, k_g = len(p_curves), len(g_curves)
    qv, pu = min(3, k_p - 1), min(3, k_g - 1)
    kv, ku = averaging_knots(big_v, qv), averaging_knots(big_u, pu)
    cp = np.stack([c.control_points for c in p_curves])  # (K, n, 3)
    cg = np.stack([c.control_points for c in g_curves])  # (L, m, 3)
    skin_p = interp_along(big_v, kv, qv, cp).transpose(1, 0, 2)  # (n, K, 3): u first
    skin_g = interp_along(big_u, ku, pu, cg)  # (L, m, 3): u first
    # crossing points on the (reparametrized) curves, averaged over profile and guide
    q = 0.5 * (np.stack([c.points(big_u) for c in p_curves]) + np.stack([c.points(big_v) for c in g_curves], axis=1))
    tensor = interp_along(big_v, kv, qv, interp_along(big_u, ku, pu, q.transpose(1, 0, 2)).transpose(1, 0, 2))
    tensor = tensor.transpose(1, 0, 2)  # (L, K, 3): u first
    net, deg, knots = _compatible_sum([
        (1.0, skin_p, (p_curves[0].degree, qv), (p_curves[0].knots, kv)),
        (1.0, skin_g, (pu, g_curves[0].degree), (ku, g_curves[0].knots)),
        (-1.0, tensor, (pu, qv), (ku, kv)),
    ])
    obj = GordonSurface._trusted(net, deg, knots, None)
    obj.profiles = tuple(prof)
    obj.guides = tuple(guid)
    obj.parameters = (checks.frozen(big_u), checks.frozen(big_v))
    obj._tol = tol
    obj.reparametrized = not exact
    return obj


GordonSurface.tolerance = property(lambda self: self._tol, doc="The requested network tolerance.")
