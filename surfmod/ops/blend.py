"""G0 / G1 / G2 blend surfaces between a boundary of one surface and a boundary of another
(:func:`blend`): an exact B-spline, one Bézier span of degree 1, 3 or 5 across, G2 to NURBS
neighbours too.  See :doc:`/guide/analysis` (section "How a blend and a fill are built").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..eval.basis import basis_matrix
from ..nets.bspline import BSplineSurface, cartesian
from ..nets.convert import as_bspline_surface
from ..readback import surface_of
from ..nets.elevate import compatible, rescaled_knots
from ..sides import SIDES, side_params
from ..surface import Surface

ORDERS = {"G0": 0, "G1": 1, "G2": 2}
ACROSS_DEGREE = {0: 1, 1: 3, 2: 5}


class BlendSurface(BSplineSurface):
    """The B-spline blend made by :func:`blend`; ``u`` runs along the boundaries
    (``v = 0`` on ``a``, ``v = 1`` on ``b``).  ``sides``, ``continuity_order`` and
    ``tension`` record how it was made."""

    occt_construct = "Geom_BSplineSurface"
    sides: tuple = ()
    continuity_order: str = "G2"
    tension: tuple = (1.0, 1.0)


def side_curves(s: BSplineSurface, side: str, order: int):
    """Homogeneous control points ``(order+1, m, 4)`` of the side curve and its outward
    cross derivatives (k-th derivative along the direction leaving the surface), with
    the side's knots and degree."""
    fixed, end = SIDES[side]
    h = s._homogeneous if s.rational else np.concatenate([s.control_points, np.ones(s.control_points.shape[:2] + (1,))], axis=-1)
    if fixed == 1:
        h = h.transpose(1, 0, 2)
    knots, p = s.knots[fixed], s.degree[fixed]
    t = np.array([s.domain[fixed][end]])
    b = basis_matrix(knots, p, h.shape[0], t, order)[:, 0, :]           # (order+1, n)
    rows = np.einsum("ki,imd->kmd", b, h)
    sign = -1.0 if end == 0 else 1.0                                    # leaving through the low end
    rows *= (sign ** np.arange(order + 1))[:, None, None]
    return rows, s.knots[1 - fixed], s.degree[1 - fixed]


def _cartesian_speed(s: Surface, side: str, samples: int = 33) -> float:
    fixed = SIDES[side][0]
    d = s.derivatives(*side_params(s, side, np.linspace(*s.domain[1 - fixed], samples)), order=1)
    cross = d[:, 1, 0] if fixed == 0 else d[:, 0, 1]
    return float(np.linalg.norm(cross, axis=1).mean())


def _normals_disagree(a: BSplineSurface, side: str, out: BSplineSurface) -> bool:
    """Does the blend's normal at the middle of its ``v = 0`` row oppose ``a``'s there?"""
    lo, hi = a.domain[1 - SIDES[side][0]]
    n_a = a.normals(*side_params(a, side, np.array([0.5 * (lo + hi)])))
    n_out = out.normals(np.array([0.5]), np.array([0.0]))
    return float(np.sum(n_a * n_out)) < 0.0


def _check_side(side, name):
    if side not in SIDES:
        raise SurfmodError(f"{name}: side must be one of u0, u1, v0, v1, got {side!r}")
    return side


def _tensions(tension):
    values = np.broadcast_to(np.asarray(tension, dtype=float), (2,)) if np.ndim(tension) <= 1 else None
    if values is None or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise SurfmodError(f"tension: expected a positive number or a pair of them, got {tension!r}")
    return float(values[0]), float(values[1])


def _rows(ca, cb, order, n, lam_a, lam_b):
    """The blend's homogeneous net ``(m, n+1, 4)``: Bézier rows across from the boundary
    curves and their scaled cross derivatives (``B' = n dP``, ``B'' = n(n-1) d2P``)."""
    net = np.empty((ca.shape[1], n + 1, 4))
    net[:, 0], net[:, n] = ca[0], cb[0]
    if order >= 1:
        net[:, 1] = ca[0] + lam_a * ca[1] / n
        net[:, n - 1] = cb[0] + lam_b * cb[1] / n
    if order >= 2:
        net[:, 2] = 2 * net[:, 1] - net[:, 0] + lam_a**2 * ca[2] / (n * (n - 1))
        net[:, n - 2] = 2 * net[:, n - 1] - net[:, n] + lam_b**2 * cb[2] / (n * (n - 1))
    return net


def blend(a: Surface, side_a: str, b: Surface, side_b: str, continuity: str = "G2", *, tension=None) -> BlendSurface:
    """An exact B-spline surface joining side ``side_a`` of ``a`` to side ``side_b`` of ``b``
    with G0, G1 or G2 continuity at both (a side is ``"u0"``, ``"u1"``, ``"v0"`` or
    ``"v1"``); ``a`` and ``b`` may also be faces (read with ``sm.from_face``, sides of
    their parameter rectangles).  The boundaries' orientations are matched automatically; ``tension``
    (a number or one per side, default 1) scales how far the blend carries the
    neighbours' cross-boundary tangents.  With rational neighbours a large tension can
    drive a weight of the blend to zero: the default then backs off (halving) until all
    weights are positive, an explicit ``tension`` raises instead.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> a = sm.BSplineSurface(net)
    >>> net2 = net + (6.0, 0.0, 2.0); net2[..., 2] += 0.1 * net2[..., 1] ** 2
    >>> b = sm.BSplineSurface(net2)
    >>> f = sm.blend(a, "u1", b, "u0", "G2")
    >>> f.degree, sm.continuity(a, f).level(), sm.continuity(f, b).level()
    ((3, 5), 'G2', 'G2')
    """
    side_a, side_b = _check_side(side_a, "side_a"), _check_side(side_b, "side_b")
    if continuity not in ORDERS:
        raise SurfmodError(f"continuity: expected one of G0, G1, G2, got {continuity!r}")
    order = ORDERS[continuity]
    auto = tension is None
    ta, tb = _tensions(1.0 if auto else tension)
    a, b = surface_of(a, "a"), surface_of(b, "b")
    sa, sb = as_bspline_surface(a, "a"), as_bspline_surface(b, "b")
    rows_a, ka, pa = side_curves(sa, side_a, order)
    rows_b, kb, pb = side_curves(sb, side_b, order)
    ka, kb = rescaled_knots(ka, 0.0, 1.0), rescaled_knots(kb, 0.0, 1.0)
    # orient b's boundary like a's
    ends_a = cartesian(rows_a[0][[0, -1]], True)[0]
    ends_b = cartesian(rows_b[0][[0, -1]], True)[0]
    straight = np.linalg.norm(ends_a - ends_b, axis=1).sum()
    crossed = np.linalg.norm(ends_a - ends_b[::-1], axis=1).sum()
    if crossed < straight:
        kb, rows_b = 1.0 - kb[::-1], rows_b[:, ::-1]
    degree, knots, (ca, cb) = compatible([(ka, pa, rows_a), (kb, pb, rows_b)], axis=1)
    # cross-boundary scales: tension times the distance to bridge over the tangent speed
    pts_a = cartesian(ca[0], True)[0]
    pts_b = cartesian(cb[0], True)[0]
    span = float(np.linalg.norm(pts_a - pts_b, axis=1).mean())
    if span <= 0.0:
        raise SurfmodError("b: the two boundaries coincide, there is nothing to blend")
    speed_a, speed_b = _cartesian_speed(sa, side_a), _cartesian_speed(sb, side_b)
    n = ACROSS_DEGREE[order]
    rational = sa.rational or sb.rational
    for _ in range(30):
        net = _rows(ca, cb, order, n, ta * span / max(speed_a, 1e-300), tb * span / max(speed_b, 1e-300))
        if not rational or np.all(net[..., 3] > 0):
            break
        if not auto:
            raise SurfmodError("tension: too large for these rational neighbours (a blend weight became <= 0)")
        ta, tb = 0.5 * ta, 0.5 * tb   # default tension: back off until every weight is positive
    pts, w = cartesian(net, True)
    across = np.concatenate([np.zeros(n + 1), np.ones(n + 1)])
    out = BlendSurface._trusted(pts, (degree, n), (knots, across), w if rational else None)
    if _normals_disagree(sa, side_a, out):  # orient the blend like a, for sewing and LocalAnalysis
        out = BlendSurface._trusted(pts[::-1], (degree, n), (1.0 - knots[::-1], across),
                                    w[::-1] if rational else None)
    out.sides, out.continuity_order, out.tension = (side_a, side_b), continuity, (ta, tb)
    return out


def occt_blend(a: Surface, side_a: str, b: Surface, side_b: str, lateral: BSplineSurface, order: str = "G1"):
    """OCCT's nearest construct on the same case, for comparison: a
    ``BRepOffsetAPI_MakeFilling`` face bounded by the side edges of ``a`` and ``b``
    (constraint ``order`` against their faces: ``"C0"`` or ``"G1"``; with ``"G2"``
    OCCT's builder refuses, "The continuity is not G0 G1 or G2", raised here as
    ``KernelError``) and by the two lateral ``v``-iso curves of
    ``lateral`` (a blend made by :func:`blend`, constrained C0).  Returns
    ``(face, face_a, face_b)``: the filling and the two neighbour faces it uses, which
    share its boundary edges.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> a, b = sm.BSplineSurface(net), sm.BSplineSurface(net + (6.0, 0.0, 2.0))
    >>> face, fa, fb = sm.ops.blend.occt_blend(a, "u1", b, "u0", sm.blend(a, "u1", b, "u0"))
    >>> sm.continuity(fa, face).g1 < 0.05
    True
    """
    from ..occ.filling import make_filling, nearest_edge

    side_a, side_b = _check_side(side_a, "side_a"), _check_side(side_b, "side_b")
    if order not in ("C0", "G1", "G2"):
        raise SurfmodError(f"order: expected C0, G1 or G2, got {order!r}")
    constraints, faces = [], []
    for s, side in ((a, side_a), (b, side_b)):
        lo, hi = s.domain[1 - SIDES[side][0]]
        point = s.points(*side_params(s, side, np.array([0.5 * (lo + hi)])))[0]
        face = s.face()
        constraints.append((nearest_edge(face, point), face, order))
        faces.append(face)
    u0, u1 = lateral.domain[0]
    for u in (u0, u1):
        constraints.append((lateral.isocurve(u=u).edge(), None, "C0"))
    return make_filling(constraints), faces[0], faces[1]
