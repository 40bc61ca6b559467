"""Filling 3-, 4- and 5-sided holes between surfaces with G1 or G2 (or G0) continuity
(:func:`fill`): a transfinite side-blending surface over a regular n-gon (Kato's scheme).

An incompatible corner raises naming it unless ``allow_singular_corners=True``; positions
and partials to order 2 are exact, the OCCT twin of each patch a bicubic approximation
within ``tolerance``.  See :doc:`/guide/analysis` (section "How a blend and a fill are built").
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..sides import SIDES
from ..surface import Surface
from .fill_domain import polygon, side_blend
from .fill_ribbons import Corner, Ribbon, check_corners, match_corners
from .from_edge import as_curve
from .offset import bicubic_approximation

__all__ = ["Corner", "Fill", "FillPatch", "fill", "occt_fill"]


class FillPatch(Surface):
    """One quadrilateral piece of a fill: the unit square mapped bilinearly onto a quad
    of the n-gon domain, then through the side-blending surface (:doc:`/guide/analysis`
    (section "How a blend and a fill are built"))."""

    exact_in_occt = False
    occt_construct = "Geom_BSplineSurface (bicubic approximation)"

    def __init__(self, ribbons, quad, tolerance, matrix=None, power=2):
        self.ribbons, self.quad, self.tolerance = ribbons, np.asarray(quad, float), float(tolerance)
        self.power = power
        self.matrix = np.eye(4) if matrix is None else matrix
        self._occ = None

    @property
    def domain(self):
        return (0.0, 1.0), (0.0, 1.0)

    def _derivatives(self, u, v, order):
        if order > 2:
            raise SurfmodError(f"order: a fill patch provides derivatives up to order 2, got {order}")
        q00, q10, q01, q11 = self.quad
        xy = ((1 - u) * (1 - v))[:, None] * q00 + (u * (1 - v))[:, None] * q10 \
            + ((1 - u) * v)[:, None] * q01 + (u * v)[:, None] * q11
        jet = side_blend(self.ribbons, xy, self.power)
        xu = (1 - v)[:, None] * (q10 - q00) + v[:, None] * (q11 - q01)
        xv = (1 - u)[:, None] * (q01 - q00) + u[:, None] * (q11 - q10)
        xuv = np.broadcast_to(q00 - q10 - q01 + q11, xu.shape)
        out = np.zeros((len(u), order + 1, order + 1, 3))
        out[:, 0, 0] = jet.v
        if order >= 1:
            out[:, 1, 0] = np.einsum("nk,nki->ni", xu, jet.g)
            out[:, 0, 1] = np.einsum("nk,nki->ni", xv, jet.g)
        if order >= 2:
            out[:, 2, 0] = np.einsum("nk,nl,nkli->ni", xu, xu, jet.h)
            out[:, 0, 2] = np.einsum("nk,nl,nkli->ni", xv, xv, jet.h)
            out[:, 1, 1] = np.einsum("nk,nl,nkli->ni", xu, xv, jet.h) + np.einsum("nk,nki->ni", xuv, jet.g)
        m = self.matrix
        out = out @ m[:3, :3].T
        out[:, 0, 0] += m[:3, 3]
        return out

    def geom(self):
        if self._occ is None:
            fit, _ = bicubic_approximation(self, np.linspace(0, 1, 9), np.linspace(0, 1, 9), self.tolerance)
            self._occ = fit.geom()
        return self._occ

    def transformed(self, matrix):
        return FillPatch(self.ribbons, self.quad, self.tolerance, transforms.affine(matrix) @ self.matrix, self.power)


class Fill(tuple):
    """The patches of a fill (one for a 4-sided hole, n for 3 and 5 sides: patch k has
    its corner where side k - 1 ends and meets sides k - 1 and k), with ``n_sides``,
    ``continuity`` and ``corners`` (a ``Corner`` per corner, where side ``index`` ends);
    ``faces()`` gives build123d faces.

    >>> import surfmod as sm
    >>> flat = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> f = sm.fill([(flat.translated((0, -1, 0)), "v1"), (flat.translated((1, 0, 0)), "u0"),
    ...              (flat.translated((0, 1, 0)), "v0"), (flat.translated((-1, 0, 0)), "u1")])
    >>> f.n_sides, f.continuity, f.corners[1].point.tolist(), f.corners[1].matched
    (4, 'G1', [1.0, 1.0, 0.0], 'G1')
    """

    n_sides: int
    continuity: str
    corners: tuple

    def faces(self):
        return [p.face() for p in self]


def _ribbon(item, index):
    if isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], Surface):
        surf, side = item
        if side not in SIDES:
            raise SurfmodError(f"boundary[{index}]: side must be one of u0, u1, v0, v1, got {side!r}")
        return Ribbon("surface", surf, side)
    if isinstance(item, Curve) or hasattr(item, "wrapped"):
        return Ribbon("curve", as_curve(item, f"boundary[{index}]"))
    raise SurfmodError(f"boundary[{index}]: expected (surface, side) or a curve/Edge, got {type(item).__name__}")


def fill(boundary, continuity: str = "G1", *, tension: float = 1.0, tolerance: float = 1e-4,
         allow_singular_corners: bool = False) -> Fill:
    """Fill the hole bounded by 3, 4 or 5 sides.  Each item of ``boundary`` is either
    ``(surface, side)`` (a side ``"u0"``, ``"u1"``, ``"v0"``, ``"v1"`` of a neighbour: the
    fill meets it with ``continuity``, ``"G0"``, ``"G1"`` or ``"G2"``) or a curve /
    build123d ``Edge`` (met with G0).
    The sides must close up end to end in the given order (either orientation each).
    ``tension`` scales the cross-boundary tangents; ``tolerance`` is for the OCCT
    B-spline twin of each patch.

    Corners: where two neighbour surfaces meet, the fill is made C1 (G1) or C2 (G2)
    through the corner point, which needs the neighbours to agree there: same normal
    for G1, and for G2 also the same curvature (true for a hole cut out of one smooth
    surface; false e.g. where two fillets of different directions meet), and the hole to
    be convex there (interior angle below 180 degrees).  If they do not,
    ``SurfmodError`` names the corner and the measured mismatch, unless
    ``allow_singular_corners``: then the fill still meets every side with ``continuity``
    up to (not including) that corner point, where its derivatives have no limit.  A
    corner next to a free-curve side is not matched (reported ``"none"``): the fill meets
    the neighbour with ``continuity`` up to that corner.  The per-corner measurements are
    in ``result.corners`` (``Corner`` records).

    >>> import numpy as np, surfmod as sm
    >>> hole = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> sides = [(hole.translated(d), s) for d, s in
    ...          (((0, -1, 0), "v1"), ((1, 0, 0), "u0"), ((0, 1, 0), "v0"), ((-1, 0, 0), "u1"))]
    >>> f = sm.fill(sides, "G2")
    >>> len(f), bool(np.allclose(f[0].points(0.3, 0.6)[2], 0.0)), [c.matched for c in f.corners]
    (1, True, ['G2', 'G2', 'G2', 'G2'])
    """
    if continuity not in ("G0", "G1", "G2"):
        raise SurfmodError(f"continuity: expected G0, G1 or G2, got {continuity!r}")
    if not isinstance(boundary, (list, tuple)) or not 3 <= len(boundary) <= 5:
        raise SurfmodError("boundary: expected a list of 3, 4 or 5 sides")
    tension = checks.positive(tension, "tension")
    tolerance = checks.positive(tolerance, "tolerance")
    ribbons = [_ribbon(item, i) for i, item in enumerate(boundary)]
    ends = [rb.curve(np.array([0.0, 1.0]))[0] for rb in ribbons]
    size = max(float(np.ptp(np.concatenate(ends), axis=0).max()), 1e-300)
    tolerance = checks.tolerance(tolerance, "tolerance", size)
    tol = 1e-6 * size
    # orient every side to start where the previous one ends
    if min(np.linalg.norm(ends[0][1] - ends[1][k]) for k in (0, 1)) > min(
            np.linalg.norm(ends[0][0] - ends[1][k]) for k in (0, 1)):
        ribbons[0].reverse, ends[0] = True, ends[0][::-1]
    for i in range(1, len(ribbons)):
        if np.linalg.norm(ends[i][1] - ends[i - 1][1]) < np.linalg.norm(ends[i][0] - ends[i - 1][1]):
            ribbons[i].reverse, ends[i] = True, ends[i][::-1]
        if np.linalg.norm(ends[i][0] - ends[i - 1][1]) > tol:
            raise SurfmodError(f"boundary[{i}]: does not start where boundary[{i - 1}] ends "
                               f"(gap {np.linalg.norm(ends[i][0] - ends[i - 1][1]):.3g})")
    if np.linalg.norm(ends[0][0] - ends[-1][1]) > tol:
        raise SurfmodError("boundary: the last side does not end where the first begins")
    # ribbon scales: the tangent of length tension * (distance to the centre) / inradius
    s = np.linspace(0.0, 1.0, 17)
    centre = np.concatenate([rb.curve(s)[0] for rb in ribbons]).mean(axis=0)
    n = len(ribbons)
    verts, _, inradius = polygon(n)
    order = {"G0": 0, "G1": 1, "G2": 2}[continuity]
    for rb in ribbons:
        rb.centre = centre
        rb.order = order
        cross = rb.cross(s)
        if cross is not None:
            reach = float(np.linalg.norm(rb.curve(s)[0] - centre, axis=1).mean())
            rb.set_scale(tension * reach / (inradius * max(float(np.linalg.norm(cross, axis=1).mean()), 1e-300)))
    corners = match_corners(ribbons, order, size)
    check_corners(corners, continuity, allow_singular_corners, list(range(n)))
    if n == 4:
        quads = [(verts[0], verts[1], verts[3], verts[2])]
    else:
        mids = 0.5 * (verts + np.roll(verts, -1, axis=0))
        centre_xy = np.zeros(2)
        quads = [(verts[k], mids[k], mids[k - 1], centre_xy) for k in range(n)]
    power = 3 if continuity == "G2" else 2
    out = Fill(FillPatch(ribbons, q, tolerance, power=power) for q in quads)
    out.n_sides, out.continuity, out.corners = n, continuity, tuple(corners)
    return out


def occt_fill(boundary, order: str = "G1"):
    """OCCT's ``BRepOffsetAPI_MakeFilling`` on the same hole: the neighbours' side edges
    with their faces as ``order`` constraints (curves as free C0 edges).  Returns the face."""
    from ..occ.filling import make_filling, nearest_edge

    constraints = []
    for i, item in enumerate(boundary):
        rb = _ribbon(item, i)
        if rb.kind == "curve":
            constraints.append((rb.source.edge(), None, "C0"))
            continue
        mid = rb.curve(np.array([0.5]))[0][0]
        face = rb.source.face()
        constraints.append((nearest_edge(face, mid), face, order))
    return make_filling(constraints)
