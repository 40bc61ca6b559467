"""``sm.OffsetSurface``: ``S + d N`` over any surfmod surface, OCCT's ``Geom_OffsetSurface``.

Positions and partials of any order come from exact jet (truncated Taylor series)
arithmetic on the base surface's partials; offsets of planes, cylinders, spheres and tori
are the elementary surfaces they are (OCCT's "equivalent surface").
"""

from __future__ import annotations

from math import factorial

import numpy as np

from .. import tolerances, transforms
from ..errors import SurfmodError
from ..eval.differential import degenerate_mask
from ..surface import Surface, require_surface
from .elementary import PlaneSurface, CylindricalSurface, SphericalSurface, ToroidalSurface


# -- offset surface ------------------------------------------------------------------------------
def _jet_product(a, b, op=None):
    """Truncated product of two bivariate Taylor jets ``(N, K, K, ...)``."""
    k_max = a.shape[1]
    shape = np.broadcast_shapes(a.shape[3:], b.shape[3:]) if op is None else (3,)
    out = np.zeros((a.shape[0], k_max, k_max) + tuple(shape))
    for i in range(k_max):
        for j in range(k_max):
            for k in range(i, k_max):
                for l in range(j, k_max):
                    x, y = a[:, i, j], b[:, k - i, l - j]
                    out[:, k, l] += op(x, y) if op is not None else x * y
    return out


def _factorials(k_max):
    f = np.array([factorial(k) for k in range(k_max)], dtype=float)
    return np.outer(f, f)


def offset_derivatives(base_ders: np.ndarray, distance: float, order: int) -> np.ndarray:
    """Partials ``(N, order+1, order+1, 3)`` of ``S + d N`` from the base surface's partials
    of order ``order + 1`` (``(N, order+2, order+2, 3)``), by exact jet (truncated
    Taylor series) arithmetic: ``n = Su x Sv``, ``N = n (n.n)^(-1/2)``."""
    k_max = order + 1
    fac = _factorials(k_max + 1)
    taylor = base_ders / fac[None, :, :, None]
    fk = _factorials(k_max)
    su = base_ders[:, 1 : k_max + 1, :k_max] / fk[None, :, :, None]
    sv = base_ders[:, :k_max, 1 : k_max + 1] / fk[None, :, :, None]
    n = _jet_product(su, sv, np.cross)
    f = _jet_product(n, n, lambda x, y: np.sum(x * y, axis=-1, keepdims=True))[..., :1]
    f0 = f[:, 0, 0, 0]
    delta = f.copy()
    delta[:, 0, 0] = 0.0
    g = np.zeros_like(f)
    power = np.zeros_like(f)
    power[:, 0, 0] = 1.0
    for m in range(2 * order + 1):
        coef = comb_half(m) * f0 ** (-0.5 - m)
        g += coef[:, None, None, None] * power
        power = _jet_product(power, delta)
    normal = _jet_product(n, g)
    out = taylor[:, :k_max, :k_max] + distance * normal
    return out * fk[None, :, :, None]


def comb_half(m: int) -> float:
    """Generalized binomial coefficient ``binom(-1/2, m)``."""
    c = 1.0
    for i in range(m):
        c *= (-0.5 - i) / (i + 1)
    return c


def _degenerate(ders):
    """``|Su x Sv|`` negligible against ``max(|Su|, |Sv|)^2`` (poles where one partial is
    round-off small but not zero, e.g. ``cos(pi/2)``)."""
    su = np.linalg.norm(ders[:, 1, 0], axis=-1)
    sv = np.linalg.norm(ders[:, 0, 1], axis=-1)
    cross = np.linalg.norm(np.cross(ders[:, 1, 0], ders[:, 0, 1]), axis=-1)
    return (cross <= 1e-9 * np.maximum(su, sv) ** 2) | degenerate_mask(ders, tolerances.DEGENERATE_NORMAL)


def _equivalent(base, d):
    """The elementary surface an offset of a plane, cylinder, sphere or torus is (same
    parametrization, like OCCT's equivalent surface), or None."""
    if not isinstance(base, (PlaneSurface, CylindricalSurface, SphericalSurface, ToroidalSurface)):
        return None
    o, x, y, z = base.frame
    if isinstance(base, PlaneSurface):
        return PlaneSurface._trusted((o + d * np.cross(x, y), x, y, z), (), *base.domain)
    (u0, u1), (v0, v1) = base.domain
    um, vm = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    if isinstance(base, SphericalSurface):
        vm = 0.0 if v0 < 0.0 < v1 else vm
    p, n = base.points(um, vm), base.normals(um, vm)
    rel = p - o
    if isinstance(base, SphericalSurface):
        radial = rel
    else:
        radial = rel - (rel @ z) * z
        if isinstance(base, ToroidalSurface):
            radial = rel - base.major * radial / np.linalg.norm(radial)
    sign = 1.0 if float(n @ radial) > 0 else -1.0
    if isinstance(base, ToroidalSurface):
        minor = base.minor + sign * d
        return ToroidalSurface._trusted(base.frame, (base.major, minor), *base.domain) if minor > 0 else None
    radius = base.radius + sign * d
    if radius <= 0:
        return None
    return type(base)._trusted(base.frame, (radius,), *base.domain)


class OffsetSurface(Surface):
    """``S(u, v) + d N(u, v)`` with ``N`` the unit normal ``Su x Sv / |Su x Sv|`` of the base
    surface: OCCT's ``Geom_OffsetSurface``.  Positions, normals and derivatives (up to
    any order) come from exact jet arithmetic on the base surface's partials; at
    degenerate points of the base the position uses the limit normal.

    >>> import surfmod as sm
    >>> s = sm.OffsetSurface(sm.sphere(2.0), 0.5)
    >>> s.points(0.0, 0.0).round(12) + 0.0
    array([2.5, 0. , 0. ])
    """

    occt_construct = "Geom_OffsetSurface"

    def __init__(self, base: Surface, distance: float):
        base = require_surface(base, "base")
        d = float(distance)
        if not np.isfinite(d):
            raise SurfmodError(f"distance: must be finite, got {distance!r}")
        self.base, self.distance = base, d
        self._equivalent = _equivalent(base, d)

    @property
    def domain(self):
        return self.base.domain

    def _grid_derivatives(self, us, vs, order):
        if self._equivalent is not None:
            return self._equivalent._grid_derivatives(us, vs, order)
        ders = self.base._grid_derivatives(us, vs, order + 1)
        flat = ders.reshape(-1, *ders.shape[2:])
        uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
        out = self._from_base(uu, vv, flat, order)
        return out.reshape(us.size, vs.size, *out.shape[1:])

    def _derivatives(self, u, v, order):
        if self._equivalent is not None:
            return self._equivalent._derivatives(u, v, order)
        return self._from_base(u, v, self.base._derivatives(u, v, order + 1), order)

    def _from_base(self, u, v, ders, order):
        bad = _degenerate(ders)
        if np.any(bad):
            (u0, u1), (v0, v1) = self.domain
            un = u[bad] + 1e-7 * ((u0 + u1) / 2 - u[bad])
            vn = v[bad] + 1e-7 * ((v0 + v1) / 2 - v[bad])
            ders[bad] = self.base._derivatives(un, vn, order + 1)
        if order == 0:  # positions only: S + d (Su x Sv)/|Su x Sv|
            n = np.cross(ders[:, 1, 0], ders[:, 0, 1])
            norm = np.linalg.norm(n, axis=-1, keepdims=True)
            out = (ders[:, 0, 0] + self.distance * n / np.where(norm > 0, norm, 1.0))[:, None, None]
        else:
            out = offset_derivatives(ders, self.distance, order)
        if np.any(bad):
            limit = self.base.normals(u[bad], v[bad])
            out[bad, 0, 0] = self.base._derivatives(u[bad], v[bad], 0)[:, 0, 0] + self.distance * limit
        return out

    def geom(self):
        from ..occ.analytic import offset_surface

        return self._twin(lambda: offset_surface(self.base.geom(), self.distance))

    def transformed(self, matrix):
        """Similarity maps only (an offset is not affine-invariant): the base is mapped and
        the distance scaled by ``|s|`` (sign flips with a mirror, as the normal does)."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            raise SurfmodError("matrix: an offset surface can only be moved by a similarity (rotation, mirror, uniform scale)")
        det = float(np.linalg.det(m[:3, :3]))
        s = abs(det) ** (1.0 / 3.0)
        return OffsetSurface(self.base.transformed(m), self.distance * s * np.sign(det))
