"""The ``Surface`` protocol every surfmod surface follows (see API.md).

A subclass supplies its parameter ``domain``, ``_derivatives(u, v, order)`` on flat,
validated parameter arrays, ``geom()`` (its OCCT twin) and ``transformed(matrix)``.
Everything else (broadcasting, grids, normals, curvature, faces, the named transforms)
is derived here once.
"""

from __future__ import annotations

import abc

import numpy as np

from . import checks, tolerances
from .eval.differential import Curvatures, curvatures, degenerate_mask, unit_normals
from .immutable import Immutable
from .transforms import mirror_matrix, rotation_matrix, scale_matrix, translation_matrix


class Surface(Immutable, abc.ABC):
    """Base of every parametric surface in surfmod.

    Parameters broadcast like NumPy ufunc arguments; results carry the broadcast shape
    in front of their own trailing axes.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> s.points([0.0, 0.5], [[0.0], [1.0]]).shape    # (2, 1) x (2,) -> (2, 2)
    (2, 2, 3)
    """

    #: True when ``geom()`` is the exact OCCT counterpart with the same parametrization.
    exact_in_occt: bool = True
    #: Name of the OCCT construct used by ``geom()`` (for tables and reports).
    occt_construct: str = "Geom_Surface"

    # -- what subclasses provide ---------------------------------------------------------
    @property
    @abc.abstractmethod
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((u0, u1), (v0, v1))``."""

    @abc.abstractmethod
    def _derivatives(self, u: np.ndarray, v: np.ndarray, order: int) -> np.ndarray:
        """``(N, order+1, order+1, 3)`` for flat in-domain parameter arrays."""

    @abc.abstractmethod
    def geom(self):
        """The OCCT ``Geom_Surface`` with the same parametrization (or the closest OCCT has)."""

    @abc.abstractmethod
    def transformed(self, matrix) -> "Surface":
        """A new surface with the 4x4 affine ``matrix`` applied to its definition."""

    def _grid_derivatives(self, us: np.ndarray, vs: np.ndarray, order: int) -> np.ndarray:
        """``(len(us), len(vs), K, K, 3)``; subclasses override with a faster tensor path."""
        uu, vv = np.meshgrid(us, vs, indexing="ij")
        out = self._derivatives(uu.ravel(), vv.ravel(), order)
        return out.reshape(us.size, vs.size, *out.shape[1:])

    # -- evaluation ----------------------------------------------------------------------
    def _params(self, u, v):
        (u0, u1), (v0, v1) = self.domain
        uu = checks.parameters(u, "u", (u0, u1))
        vv = checks.parameters(v, "v", (v0, v1))
        uu, vv = np.broadcast_arrays(uu, vv)
        return uu.shape, uu.ravel(), vv.ravel()

    def points(self, u, v) -> np.ndarray:
        """Positions ``S(u, v)``, shape ``broadcast(u, v).shape + (3,)``.

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).points(0.5, 0.25)
        array([0.5 , 0.25, 0.  ])
        """
        shape, uf, vf = self._params(u, v)
        return self._derivatives(uf, vf, 0)[:, 0, 0, :].reshape(*shape, 3)

    def derivatives(self, u, v, order: int = 1) -> np.ndarray:
        """Partials ``[..., k, l, :] = d^(k+l) S / du^k dv^l`` for ``k, l <= order``.

        At an interior knot where a derivative jumps (multiplicity above degree minus
        the order) the right-hand derivative is returned; at the end of the domain the
        left-hand one.

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)).derivatives(0.5, 0.5)[1, 0]
        array([2., 0., 0.])
        """
        order = checks.count(order, "order", minimum=0)
        shape, uf, vf = self._params(u, v)
        out = self._derivatives(uf, vf, order)
        return out.reshape(*shape, order + 1, order + 1, 3)

    def grid(self, us, vs) -> np.ndarray:
        """Positions on the tensor grid ``us x vs``: ``(len(us), len(vs), 3)``."""
        return self.grid_derivatives(us, vs, 0)[:, :, 0, 0, :]

    def grid_chunks(self, us, vs, max_points: int = 1 << 21):
        """Evaluate a huge grid block by block with bounded memory.

        Yields ``(i0, block)`` where ``block = grid(us[i0:i1], vs)``; each block holds at
        most about ``max_points`` points (at least one row of u).

        >>> import surfmod as sm, numpy as np
        >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
        >>> [(i0, b.shape) for i0, b in s.grid_chunks(np.linspace(0, 1, 5), np.linspace(0, 1, 4), 8)]
        [(0, (2, 4, 3)), (2, (2, 4, 3)), (4, (1, 4, 3))]
        """
        us = np.atleast_1d(np.asarray(us, dtype=float)).ravel()
        vs = np.atleast_1d(np.asarray(vs, dtype=float)).ravel()
        max_points = checks.count(max_points, "max_points")
        rows = max(1, max_points // max(1, vs.size))
        for i0 in range(0, us.size, rows):
            yield i0, self.grid(us[i0 : i0 + rows], vs)

    def grid_derivatives(self, us, vs, order: int = 1) -> np.ndarray:
        """Partials on the tensor grid: ``(len(us), len(vs), order+1, order+1, 3)``."""
        order = checks.count(order, "order", minimum=0)
        (u0, u1), (v0, v1) = self.domain
        us = checks.parameters(np.atleast_1d(us), "us", (u0, u1)).ravel()
        vs = checks.parameters(np.atleast_1d(vs), "vs", (v0, v1)).ravel()
        return self._grid_derivatives(us, vs, order)

    # -- differential geometry -----------------------------------------------------------
    def _regular_derivatives(self, uf: np.ndarray, vf: np.ndarray, order: int) -> np.ndarray:
        """Derivatives where degenerate points (poles, collapsed edges) are replaced by
        the values a short step towards the domain centre, i.e. the limit from inside."""
        ders = self._derivatives(uf, vf, order)
        bad = degenerate_mask(ders, tolerances.DEGENERATE_NORMAL)
        if np.any(bad):
            (u0, u1), (v0, v1) = self.domain
            step = 1e-7
            un = uf[bad] + step * ((u0 + u1) / 2 - uf[bad])
            vn = vf[bad] + step * ((v0 + v1) / 2 - vf[bad])
            for _ in range(6):  # widen the step until the normal is defined
                nd = self._derivatives(un, vn, order)
                still = degenerate_mask(nd, tolerances.DEGENERATE_NORMAL)
                ders[bad] = nd
                if not np.any(still):
                    break
                step *= 30.0
                un = uf[bad] + step * ((u0 + u1) / 2 - uf[bad])
                vn = vf[bad] + step * ((v0 + v1) / 2 - vf[bad])
        return ders

    def normals(self, u, v) -> np.ndarray:
        """Unit normals in the direction of ``Su x Sv``, shape ``(..., 3)``.

        At a degenerate point (a pole of a sphere, the apex of a cone, a collapsed edge)
        ``Su x Sv`` vanishes; the normal returned there is the limit taken from inside
        the domain, so the result is always a unit vector, never NaN.

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).normals(0.3, 0.3)
        array([0., 0., 1.])
        """
        shape, uf, vf = self._params(u, v)
        return unit_normals(self._regular_derivatives(uf, vf, 1)).reshape(*shape, 3)

    def curvatures(self, u, v) -> Curvatures:
        """Gaussian, mean and principal curvatures (``k1 >= k2``), signed against ``normals``.

        Degenerate points use the limit from inside the domain, as :meth:`normals` does.
        """
        shape, uf, vf = self._params(u, v)
        c = curvatures(self._regular_derivatives(uf, vf, 2))
        return Curvatures(*(a.reshape(shape) for a in c))

    # -- OCCT twins ----------------------------------------------------------------------
    def face(self):
        """A build123d ``Face`` over the whole domain.

        >>> import surfmod as sm
        >>> round(sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)).face().area, 9)
        6.0
        """
        from .occ.topo import face_from_surface

        (u0, u1), (v0, v1) = self.domain
        return face_from_surface(self.geom(), u0, u1, v0, v1)

    # -- named transforms (all through ``transformed``) ----------------------------------
    def translated(self, vector) -> "Surface":
        """A copy moved by ``vector``."""
        return self.transformed(translation_matrix(vector))

    def rotated(self, axis_origin, axis_direction, degrees: float) -> "Surface":
        """A copy rotated by ``degrees`` about the axis (right-hand rule)."""
        return self.transformed(rotation_matrix(axis_origin, axis_direction, degrees))

    def mirrored(self, point, normal) -> "Surface":
        """A copy mirrored in the plane through ``point`` with ``normal``."""
        return self.transformed(mirror_matrix(point, normal))

    def scaled(self, factor, center=(0.0, 0.0, 0.0)) -> "Surface":
        """A copy scaled about ``center``; ``factor`` is a number or three (non-uniform)."""
        return self.transformed(scale_matrix(factor, center))
