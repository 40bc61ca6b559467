"""The ``Surface`` protocol every surfmod surface follows (see API.md).

A subclass supplies its parameter ``domain``, ``_derivatives(u, v, order)`` on flat,
validated parameter arrays, ``geom()`` (its OCCT twin) and ``transformed(matrix)``.
Everything else (broadcasting, grids, normals, curvature, faces) is derived here once;
the named transforms come from ``transforms.Transformable``.
"""

from __future__ import annotations

import abc

import numpy as np

from . import checks, pictures, tolerances
from .errors import SurfmodError
from .eval.differential import Curvatures, curvatures, degenerate_mask, unit_normals
from .immutable import Immutable
from .transforms import Transformable


def all_finite(out: np.ndarray) -> bool:
    """Whether every value of ``out`` is finite.  The sum is one vectorized pass without
    a boolean temporary: a NaN or an infinity makes it non-finite, so a finite sum proves
    every term finite; only a non-finite sum (or one that overflowed) needs the exact test.

    >>> all_finite(np.array([1.0, -1e308, -1e308])), all_finite(np.array([1.0, np.nan]))
    (True, False)
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(out.sum()):
            return True
    return bool(np.isfinite(out).all())


def require_surface(value, name: str = "s") -> "Surface":
    """``value`` itself if it is a surfmod :class:`Surface`, else a SurfmodError naming ``name``.

    >>> require_surface("plane", "s")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: s: expected a surfmod Surface, got str
    """
    if not isinstance(value, Surface):
        raise SurfmodError(f"{name}: expected a surfmod Surface, got {type(value).__name__}")
    return value


def finite_result(out: np.ndarray, u: np.ndarray, v: np.ndarray, what: str) -> np.ndarray:
    """``out`` (one row per parameter pair) when every value is finite; otherwise a
    ``SurfmodError`` naming the first parameters where the surface has no finite value."""
    if all_finite(out):
        return out
    i = int(np.argmax(~np.isfinite(out.reshape(len(out), -1)).all(axis=1)))
    raise SurfmodError(
        f"u, v: the {what} at (u, v) = ({u[i]:.17g}, {v[i]:.17g}) are not finite "
        "(the surface is singular or overflows there)"
    )


def model_size(*surfaces, samples: int = 9) -> float:
    """The bounding-box diagonal of ``samples`` x ``samples`` points of each surface (the
    scale that tolerances are judged against; the tessellators sample 17 x 17).

    >>> import surfmod as sm
    >>> round(model_size(sm.plane((0, 0, 0), (3, 0, 0), (0, 4, 0))), 12)
    5.0
    """
    pts = []
    for s in surfaces:
        (u0, u1), (v0, v1) = s.domain
        us, vs = np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)
        pts.append(s._grid_derivatives(us, vs, 0)[:, :, 0, 0].reshape(-1, 3))
    pts = np.concatenate(pts)
    with np.errstate(invalid="ignore", over="ignore"):
        size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    return size if np.isfinite(size) else 0.0


class Surface(Transformable, Immutable, abc.ABC):
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

    def _finite_partials(self, order: int) -> bool:
        """True when every partial up to ``order`` (0: positions) is finite by construction,
        so no pass over the output is needed; subclasses that can bound them override."""
        return False

    def _closest_parameters(self, points: np.ndarray):
        """``(u, v)`` of the closest points of the domain to ``(N, 3)`` points where the
        surface has them in closed form (the elementary surfaces), else ``None``: then
        :func:`surfmod.ops.closest.closest_points` seeds and iterates."""
        return None

    def _grid_derivatives(self, us: np.ndarray, vs: np.ndarray, order: int) -> np.ndarray:
        """``(len(us), len(vs), K, K, 3)``; subclasses override with a faster tensor path."""
        uu, vv = np.meshgrid(us, vs, indexing="ij")
        out = self._derivatives(uu.ravel(), vv.ravel(), order)
        return out.reshape(us.size, vs.size, *out.shape[1:])

    # -- evaluation ----------------------------------------------------------------------
    def _params(self, u, v, per_point: int = 1, max_points: int = checks.MAX_POINTS):
        """``(shape, u, v)``: validated, broadcast, flat; refuses empty or non-broadcasting
        arrays and results above ``max_points``."""
        return checks.parameter_pair(u, v, self.domain, per_point=per_point, max_points=max_points)

    def points(self, u, v, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Positions ``S(u, v)``, shape ``broadcast(u, v).shape + (3,)``.

        ``u`` and ``v`` must broadcast together; more than ``max_points`` results are
        refused up front (pass a larger ``max_points`` to allow them).

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).points(0.5, 0.25)
        array([0.5 , 0.25, 0.  ])
        """
        shape, uf, vf = self._params(u, v, max_points=max_points)
        out = self._evaluate(uf, vf, 0)[:, 0, 0, :]
        if not self._finite_partials(0):
            out = finite_result(out, uf, vf, "points")
        return out.reshape(*shape, 3)

    def derivatives(self, u, v, order: int = 1, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Partials ``[..., k, l, :] = d^(k+l) S / du^k dv^l`` for ``k, l <= order``.

        At an interior knot where a derivative jumps (multiplicity above degree minus
        the order) the right-hand derivative is returned; at the end of the domain the
        left-hand one.

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)).derivatives(0.5, 0.5)[1, 0]
        array([2., 0., 0.])
        """
        order = checks.derivative_order(order)
        shape, uf, vf = self._params(u, v, (order + 1) ** 2, max_points)
        out = self._evaluate(uf, vf, order)
        if not self._finite_partials(order):
            out = finite_result(out, uf, vf, "derivatives")
        return out.reshape(*shape, order + 1, order + 1, 3)

    def grid(self, us, vs, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Positions on the tensor grid ``us x vs``: ``(len(us), len(vs), 3)``.

        Grids of more than ``max_points`` points are refused up front (evaluate a bigger
        one block by block with :meth:`grid_chunks`, or raise ``max_points``).

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).grid([0, 1], [0, 0.5, 1]).shape
        (2, 3, 3)
        """
        return self.grid_derivatives(us, vs, 0, max_points=max_points)[:, :, 0, 0, :]

    def grid_chunks(self, us, vs, max_points: int = 1 << 21):
        """Evaluate a huge grid block by block with bounded memory.

        Yields ``(i0, block)`` where ``block = grid(us[i0:i1], vs)``; each block holds at
        most about ``max_points`` points (at least one row of u).

        >>> import surfmod as sm, numpy as np
        >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
        >>> [(i0, b.shape) for i0, b in s.grid_chunks(np.linspace(0, 1, 5), np.linspace(0, 1, 4), 8)]
        [(0, (2, 4, 3)), (2, (2, 4, 3)), (4, (1, 4, 3))]
        """
        us = checks.parameters(us, "us", self.domain[0]).ravel()
        vs = checks.parameters(vs, "vs", self.domain[1]).ravel()
        max_points = checks.count(max_points, "max_points")
        rows = max(1, max_points // max(1, vs.size))
        for i0 in range(0, us.size, rows):
            yield i0, self.grid(us[i0 : i0 + rows], vs, max_points=max(max_points, vs.size))

    def grid_derivatives(self, us, vs, order: int = 1, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Partials on the tensor grid: ``(len(us), len(vs), order+1, order+1, 3)``."""
        order = checks.derivative_order(order)
        us, vs = checks.parameter_grid(us, vs, self.domain, (order + 1) ** 2, max_points)
        if us.size == 0 or vs.size == 0:  # NumPy-style: empty in, empty out
            return np.empty((us.size, vs.size, order + 1, order + 1, 3))
        out = self._grid_derivatives(us, vs, order)
        if not self._finite_partials(order) and not all_finite(out):
            bad = np.argwhere(~np.isfinite(out))[0]
            finite_result(out[bad[0], bad[1]][None], us[bad[:1]], vs[bad[1:2]], "grid")
        return out

    def _evaluate(self, uf: np.ndarray, vf: np.ndarray, order: int) -> np.ndarray:
        """``_derivatives`` that also takes empty arrays (subclasses need not)."""
        if uf.size == 0:
            return np.empty((0, order + 1, order + 1, 3))
        return self._derivatives(uf, vf, order)

    # -- differential geometry -----------------------------------------------------------
    def _regular_derivatives(self, uf: np.ndarray, vf: np.ndarray, order: int) -> np.ndarray:
        """Derivatives where degenerate points (poles, collapsed edges) are replaced by
        the values a short step towards the domain centre, i.e. the limit from inside."""
        ders = self._evaluate(uf, vf, order)
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

    def normals(self, u, v, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Unit normals in the direction of ``Su x Sv``, shape ``(..., 3)``.

        At a degenerate point (a pole of a sphere, the apex of a cone, a collapsed edge)
        ``Su x Sv`` vanishes; the normal returned there is the limit taken from inside
        the domain, so the result is always a unit vector, never NaN.

        >>> import surfmod as sm
        >>> sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).normals(0.3, 0.3)
        array([0., 0., 1.])
        """
        shape, uf, vf = self._params(u, v, 2, max_points)
        return finite_result(unit_normals(self._regular_derivatives(uf, vf, 1)), uf, vf, "normals").reshape(*shape, 3)

    def curvatures(self, u, v, *, max_points: int = checks.MAX_POINTS) -> Curvatures:
        """Gaussian, mean and principal curvatures (``k1 >= k2``), signed against ``normals``.

        Degenerate points use the limit from inside the domain, as :meth:`normals` does.
        """
        shape, uf, vf = self._params(u, v, 9, max_points)
        c = curvatures(self._regular_derivatives(uf, vf, 2))
        finite_result(np.stack(c, axis=-1), uf, vf, "curvatures")
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

    def _repr_png_(self) -> bytes | None:
        """A shaded picture for Jupyter (see :func:`surfmod.meshing.render.png_bytes`)."""
        return pictures.repr_png(self)
