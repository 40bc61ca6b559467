"""Swept surfaces (:func:`sweep`): a profile curve moved along a path curve by a moving frame,
the lecture's four swept surfaces as one formula.

Derivatives in ``u`` are exact, in ``v`` 5-point central differences (about 1e-9 relative).
The same concept as :mod:`surfmod.occ.sweep`, its OCCT twin (the pipe shell, which only
approximates the surface) behind the kernel door.  See :doc:`/guide/surfaces` (section
"Swept surfaces").
"""

from __future__ import annotations

import numpy as np

from .. import checks, tolerances, transforms
from ..errors import KernelError, SurfmodError
from ..eval.basis import basis_matrix
from ..eval.frames import RotationMinimizingTable, any_normal, axis_rotation, frenet_frames
from ..inputs import build123d_face
from ..nets.bspline import BSplineCurve
from ..surface import Surface
from .fitting import averaging_knots
from .from_edge import as_curve

MODES = ("frenet", "corrected_frenet")

# 5-point difference stencils: central, forward, backward (offsets in steps, weights)
_STENCIL_OFFSETS = np.array([[-2, -1, 0, 1, 2], [0, 1, 2, 3, 4], [0, -1, -2, -3, -4]], dtype=float)
_STENCIL_D1 = np.array([[1, -8, 0, 8, -1], [-25, 48, -36, 16, -3], [25, -48, 36, -16, 3]], dtype=float) / 12
_STENCIL_D2 = np.array([[-1, 16, -30, 16, -1], [35, -104, 114, -56, 11], [35, -104, 114, -56, 11]], dtype=float) / 12
_STENCIL_CENTER = np.array([2, 0, 0])
_TABLE = 1025  # samples of the frame table along the path


class SweptSurface(Surface):
    """A swept surface (the formula: :doc:`/guide/surfaces` (section "Swept surfaces")).

    Attributes: ``profile``, ``path``, ``end_profile``, ``guide`` (surfmod curves),
    ``twist`` (degrees), ``mode``; ``tolerance`` is the pass threshold of the geometric
    cross-check (``1e-4`` times the size of the surface).

    >>> import surfmod as sm
    >>> s = sm.sweep(sm.Line((-1, 0, 0), (1, 0, 0)), sm.Line((0, 0, 0), (0, 0, 5)), twist=90)
    >>> (s.points(0.0, 5.0).round(12) + 0.0).tolist()   # the blade turned a quarter at the top
    [0.0, -1.0, 5.0]
    """

    exact_in_occt = False
    occt_construct = "BRepOffsetAPI_MakePipeShell"

    def __init__(self, profile, path, *, end_profile=None, twist: float = 0.0, mode: str = "frenet", guide=None,
                 guide_scale: bool = False):
        self.profile = as_curve(profile, "profile")
        self.path = as_curve(path, "path")
        self.end_profile = None if end_profile is None else as_curve(end_profile, "end_profile")
        self.guide = None if guide is None else as_curve(guide, "guide")
        self.twist = checks.angle(twist, "twist")
        if not isinstance(mode, str) or mode not in MODES:
            raise SurfmodError(f"mode: expected one of {MODES}, got {mode!r}")
        self.mode = mode
        self.guide_scale = bool(guide_scale)
        if self.guide_scale and self.guide is None:
            raise SurfmodError("guide_scale: scaling to a guide rail needs guide=")
        if self.guide_scale and self.end_profile is not None:
            raise SurfmodError("guide_scale: the guide sets the section size, it cannot be combined with end_profile")
        self._prepare()

    # -- construction ----------------------------------------------------------------------
    def _prepare(self):
        v0, v1 = self.path.domain
        ts = np.linspace(v0, v1, _TABLE)
        d = self.path._derivatives(ts, 2)
        speed = np.linalg.norm(d[:, 1], axis=-1)
        size = max(float(np.ptp(d[:, 0], axis=0).max()), 1e-300)
        scale = max(float(speed.max()), 1e-300)
        tang = d[:, 1] / np.where(speed > 0, speed, 1.0)[:, None]
        bad = speed <= 1e-9 * scale
        turn = np.sum(tang[1:] * tang[:-1], axis=-1) < 0.0  # tangent reverses between samples
        if np.any(bad) or np.any(turn):
            i = int(np.argmax(bad)) if np.any(bad) else int(np.argmax(turn))
            raise SurfmodError(f"path: has a cusp (zero or reversing tangent) near t = {ts[i]:g}")
        self._size = size
        self._v = (float(v0), float(v1))
        self._straight = False
        if self.guide is not None:
            self._guide_prepare()
            if self.guide_scale:
                self._dist0 = 1.0
                self._dist0 = float(self._guide_scale(np.array([float(v0)]))[0])
        elif self.mode == "frenet":
            _, kappa = frenet_frames(d[:, 1], d[:, 2])
            flat = kappa * size <= 1e-9
            if np.all(flat):
                self._straight = True
                self._n0 = any_normal(tang[0])
            elif np.any(flat):
                i = int(np.argmax(flat))
                raise SurfmodError(
                    f"path: the curvature vanishes near t = {ts[i]:g}, the Frenet frame is undefined there "
                    "(use mode='corrected_frenet')"
                )
        if self.guide is None and (self.mode == "corrected_frenet" or self._straight):
            frames, kappa = frenet_frames(d[:1, 1], d[:1, 2])
            n0 = frames[0][:, 1] if kappa[0] * size > 1e-9 else any_normal(tang[0])
            self._rmf = RotationMinimizingTable(ts, d[:, 0], tang, n0)
        # local coordinates of the sections in their frames
        p = self.path._derivatives(np.array([v0, v1]), 0)[:, 0]
        r = self._frames(np.array([v0, v1]))
        self._p0, self._r0, self._p1, self._r1 = p[0], r[0], p[1], r[1]
        if self.end_profile is not None:
            self._check_end_orientation()
        self._tolerance = tolerances.GEOMETRIC_TOL * max(1.0, self._extent())

    def _check_end_orientation(self):
        """The end section must run the same way as the start section, seen in the
        path's frame (else the blend would turn inside out; OCCT flips it silently)."""
        u = np.linspace(*self.profile.domain, 65)
        la, lb = (x[:, 0] for x in self._local(u, 0))
        closed = np.linalg.norm(la[-1] - la[0]) <= 1e-9 * self._size
        if closed:
            area = lambda q: np.sum(np.cross(q[:-1] - q.mean(0), q[1:] - q.mean(0)), axis=0)  # noqa: E731
            opposite = float(area(la) @ area(lb)) < 0.0
        else:
            same = np.linalg.norm(la[0] - lb[0]) + np.linalg.norm(la[-1] - lb[-1])
            opposite = np.linalg.norm(la[0] - lb[-1]) + np.linalg.norm(la[-1] - lb[0]) < same
        if opposite:
            raise SurfmodError("end_profile: runs opposite to profile in the path's frame (reverse it)")

    def _extent(self):
        (u0, u1) = self.profile.domain
        us = np.linspace(u0, u1, 9)
        vs = np.linspace(*self._v, 9)
        pts = self._derivatives(np.repeat(us, 9), np.tile(vs, 9), 0)[:, 0, 0]
        return float(np.ptp(pts, axis=0).max())

    def _guide_prepare(self):
        g0, g1 = self.guide.domain
        self._g = (float(g0), float(g1))
        self._gtab = None
        # solve once on a table along the path; later solves start from its interpolant
        ts = np.linspace(*self._v, 257)
        d = self.path._derivatives(ts, 1)
        t = d[:, 1] / np.linalg.norm(d[:, 1], axis=-1)[:, None]
        self._gtab = (ts, self._guide_params(ts, d[:, 0], t, iterations=60))

    def _guide_params(self, v, p, t, iterations=30):
        """Guide parameters of the normal-plane crossings (vectorized Newton)."""
        (v0, v1), (g0, g1) = self._v, self._g
        if self._gtab is None:
            s = g0 + (v - v0) / (v1 - v0) * (g1 - g0)
        else:
            s = np.interp(v, *self._gtab)
        for _ in range(iterations):
            gd = self.guide._derivatives(s, 1)
            f = np.sum((gd[:, 0] - p) * t, axis=-1)
            df = np.sum(gd[:, 1] * t, axis=-1)
            step = f / np.where(np.abs(df) > 0, df, 1.0)
            s = np.clip(s - step, g0, g1)
            if np.max(np.abs(f)) <= 1e-13 * self._size:
                break
        return s

    def _guide_scale(self, v):
        """Distance from the path to the guide in the normal plane, relative to the start."""
        d = self.path._derivatives(v, 1)
        t = d[:, 1] / np.linalg.norm(d[:, 1], axis=-1)[:, None]
        return self._guide_points(v, d[:, 0], t, distances=True) / self._dist0

    def _guide_points(self, v, p, t, distances=False):
        """The guide point in the normal plane of the path at each ``v`` (Newton on the
        guide parameter, vectorized; start at the same normalized parameter): the unit
        normal towards it (or the distances to it)."""
        s = self._guide_params(v, p, t)
        q = self.guide._derivatives(s, 0)[:, 0]
        miss = np.abs(np.sum((q - p) * t, axis=-1)) > 1e-9 * self._size
        if np.any(miss):
            raise SurfmodError(
                f"guide: does not cross the normal plane of the path at t = {v[np.argmax(miss)]:g} "
                "(extend the guide so that it spans the whole path)"
            )
        off = q - p
        off = off - np.sum(off * t, axis=-1, keepdims=True) * t
        norm = np.linalg.norm(off, axis=-1)
        if np.any(norm <= 1e-12 * self._size):
            raise SurfmodError("guide: touches the path, the normal towards it is undefined")
        if distances:
            return norm
        return off / norm[:, None]

    # -- frames ----------------------------------------------------------------------------
    def _frames(self, v, with_twist=True):
        d = self.path._derivatives(v, 2)
        speed = np.linalg.norm(d[:, 1], axis=-1)
        t = d[:, 1] / speed[:, None]
        if self.guide is not None:
            n = self._guide_points(v, d[:, 0], t)
            r = np.stack([t, n, np.cross(t, n)], axis=-1)
        elif self.mode == "frenet" and not self._straight:
            r = frenet_frames(d[:, 1], d[:, 2])[0]
        else:
            r = self._rmf.frames(v, d[:, 0], t)
        if with_twist and self.twist != 0.0:
            r = r @ axis_rotation(np.radians(self.twist) * self._weight(v))
        return r

    def frames(self, v) -> np.ndarray:
        """The moving frame (twist included) at path parameters ``v``: ``(..., 3, 3)``
        with columns tangent, normal, binormal."""
        vv = checks.parameters(v, "v", self._v)
        return self._frames(vv.ravel()).reshape(vv.shape + (3, 3))

    def _weight(self, v):
        v0, v1 = self._v
        return (v - v0) / (v1 - v0)

    # -- the Surface protocol ----------------------------------------------------------------
    @property
    def domain(self):
        return tuple(map(float, self.profile.domain)), self._v

    @property
    def tolerance(self) -> float:
        """Pass threshold of the geometric cross-check (1e-4 x the surface size)."""
        return self._tolerance

    def _local(self, u, order):
        """Blended local section derivatives ``(N, order+1, 3)`` for both sections."""
        a = self.profile._derivatives(u, order).copy()
        a[:, 0] -= self._p0
        la = a @ self._r0  # R0^T x for row vectors
        if self.end_profile is None:
            return la, la
        (u0, u1), (e0, e1) = self.profile.domain, self.end_profile.domain
        scale = (e1 - e0) / (u1 - u0)
        ue = e0 + (u - u0) * scale
        b = self.end_profile._derivatives(ue, order).copy()
        b[:, 0] -= self._p1
        b *= scale ** np.arange(order + 1)[None, :, None]  # chain rule for the mapped parameter
        return la, b @ self._r1

    def _derivatives(self, u, v, order):
        """``(N, order+1, order+1, 3)`` with v-derivatives by 5-point differences."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        if order > 2:
            raise SurfmodError(f"order: swept surfaces provide derivatives up to order 2, got {order}")
        la, lb = self._local(u, order)
        v0, v1 = self._v
        n = u.size
        if order == 0:
            offsets = np.zeros((1, n))
        else:
            h = 1e-3 * (v1 - v0)
            kind = self._stencil_kind(v, 2 * h)
            offsets = _STENCIL_OFFSETS[kind].T * h  # (5, N)
        vv = (v[None, :] + offsets).ravel()
        p = self.path._derivatives(vv, 0)[:, 0].reshape(offsets.shape[0], n, 3)
        r = self._frames(vv).reshape(offsets.shape[0], n, 3, 3)
        w = self._weight(vv).reshape(offsets.shape[0], n)
        loc = (1.0 - w)[..., None, None] * la[None] + w[..., None, None] * lb[None]  # (S, N, K, 3)
        if self.guide_scale:
            loc = loc * self._guide_scale(vv).reshape(offsets.shape[0], n)[..., None, None]
        g = np.einsum("snij,snkj->snki", r, loc)
        g[:, :, 0] += p
        out = np.zeros((n, order + 1, order + 1, 3))
        if order == 0:
            out[:, 0, 0] = g[0, :, 0]
            return out
        c1 = _STENCIL_D1[kind].T[:, :, None, None] / h  # (5, N, 1, 1)
        c2 = _STENCIL_D2[kind].T[:, :, None, None] / (h * h)
        d1 = np.sum(c1 * g, axis=0)
        d2 = np.sum(c2 * g, axis=0)
        g0 = g[_STENCIL_CENTER[kind], np.arange(n)]
        for k in range(order + 1):
            out[:, k, 0] = g0[:, k]
            if k + 1 <= order:
                out[:, k, 1] = d1[:, k]
            if k + 2 <= order:
                out[:, k, 2] = d2[:, k]
        return out

    def _stencil_kind(self, v, reach):
        """0 central, 1 forward, 2 backward: keep the difference stencil inside the
        smooth piece of the path (between its knots, inside the domain)."""
        v0, v1 = self._v
        knots = getattr(self.path, "knots", None)
        breaks = np.unique(np.concatenate([[v0, v1], [] if knots is None else np.asarray(knots, dtype=float)]))
        breaks = breaks[(breaks >= v0) & (breaks <= v1)]
        i = np.clip(np.searchsorted(breaks, v, side="right") - 1, 0, breaks.size - 2)
        lo, hi = breaks[i], breaks[i + 1]
        kind = np.zeros(v.size, dtype=int)
        kind[v + reach > hi] = 2
        kind[v - reach < lo] = 1
        return kind

    # -- OCCT twin -----------------------------------------------------------------------------
    def _pipe(self):
        cached = getattr(self, "_pipe_cache", None)
        if cached is not None:
            return cached
        from ..occ.sweep import pipe_shell

        profiles = self._profiles()
        if self.guide is not None:
            law = None
            if self.guide_scale:
                vs = np.linspace(*self._v, 201)
                law = (vs, self._guide_scale(vs))
            shape, faces = pipe_shell(profiles, _occ(self.path), mode="auxiliary", auxiliary=_occ(self.guide),
                                      scale_law=law)
        elif self.mode == "frenet" and self.twist == 0.0 and not self._straight:
            shape, faces = pipe_shell(profiles, _occ(self.path), mode="frenet")
        else:
            # OCCT's own CorrectedFrenet law is a coarse approximation of the
            # rotation-minimizing frame (about ten angle samples, then smoothed); the
            # auxiliary spine traced from our frame makes OCCT sweep *our* definition.
            # OCCT finds the rail point in the normal plane: a rail close to the path
            # keeps that intersection unique (coiled paths), so shrink it on failure.
            for offset in (0.05, 0.01, 0.002):
                try:
                    rail = _occ(self._frame_rail(offset))
                    shape, faces = pipe_shell(profiles, _occ(self.path), mode="auxiliary", auxiliary=rail)
                    break
                except KernelError:
                    if offset == 0.002:
                        raise
        if len(faces) != 1:
            raise SurfmodError(f"profile: the pipe shell has {len(faces)} faces, expected one")
        self._pipe_cache = (shape, faces[0])
        return self._pipe_cache

    def occt_native(self):
        """The pipe-shell face from OCCT's own trihedron law for ``mode`` (Frenet or
        CorrectedFrenet, no auxiliary spine), for measuring how far OCCT's
        CorrectedFrenet is from the exact rotation-minimizing frame."""
        from ..occ.sweep import pipe_shell

        return build123d_face(pipe_shell(self._profiles(), _occ(self.path), mode=self.mode)[1][0])

    def _profiles(self) -> list:
        return [_occ(c) for c in (self.profile, self.end_profile) if c is not None]

    def _frame_rail(self, offset=0.05):
        """An auxiliary spine for OCCT: the path offset along our (twisted) normal,
        traced densely and interpolated, so that OCCT's 'normal towards the auxiliary
        spine' is our frame's normal."""
        v0, v1 = self._v
        vs = np.linspace(v0, v1, 201)
        p = self.path._derivatives(vs, 0)[:, 0]
        r = self._frames(vs)
        pts = p + offset * self._size * r[:, :, 1]
        t = (vs - v0) / (v1 - v0)
        k = averaging_knots(t, 3)
        ctrl = np.linalg.solve(basis_matrix(k, 3, t.size, t)[0], pts)
        return BSplineCurve._trusted(ctrl, 3, k)

    def geom(self):
        """The ``Geom_Surface`` of the pipe-shell face (OCCT's approximation)."""
        from ..occ.topo import face_surface

        surf, bounds, _rev = face_surface(self._pipe()[1])
        self.occ_bounds = bounds
        return surf

    def face(self):
        """The pipe-shell face itself (build123d ``Face``)."""
        return build123d_face(self._pipe()[1])

    def transformed(self, matrix) -> "SweptSurface":
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            raise SurfmodError("matrix: a swept surface can only be moved by a similarity (frames are orthonormal)")
        return SweptSurface(
            self.profile.transformed(m),
            self.path.transformed(m),
            end_profile=None if self.end_profile is None else self.end_profile.transformed(m),
            twist=self.twist * np.sign(np.linalg.det(m[:3, :3])),
            mode=self.mode,
            guide=None if self.guide is None else self.guide.transformed(m),
            guide_scale=self.guide_scale,
        )


def _occ(curve) -> tuple:
    """A curve as the pipe shell takes it: its B-spline's ``Geom_BSplineCurve`` and domain."""
    c = curve.to_bspline()
    return (c.geom(), *c.domain)


def sweep(profile, path, *, end_profile=None, twist: float = 0.0, mode: str = "frenet", guide=None,
          guide_scale: bool = False) -> SweptSurface:
    """The swept surface of ``profile`` along ``path`` (see :mod:`surfmod.construct.sweep`).

    ``mode`` ``"frenet"`` or ``"corrected_frenet"`` (rotation-minimizing); ``end_profile``
    blends to a second section at the path end; ``guide`` turns the frame towards a
    guide rail (``guide_scale=True`` also scales the section, about the path, with the
    rail's distance from the path); ``twist`` (degrees) turns it linearly about the
    tangent.

    >>> import surfmod as sm, numpy as np
    >>> path = sm.BSplineCurve([(0, 0, 0), (0, 0, 4), (3, 0, 8), (8, 0, 9)], 3)
    >>> circle = sm.BezierCurve([(1, 0, 0), (1, 1, 0), (0, 1, 0)], weights=[1, 2 ** -0.5, 1])
    >>> s = sm.sweep(circle, path, mode="corrected_frenet")
    >>> # every section stays at its distance from the path: |S(u, v) - P(v)| = 1
    >>> p = s.points(np.array([0.0, 0.3, 1.0]), 0.7) - path.points(0.7)
    >>> np.round(np.linalg.norm(p, axis=-1), 12).tolist()
    [1.0, 1.0, 1.0]
    """
    return SweptSurface(profile, path, end_profile=end_profile, twist=twist, mode=mode, guide=guide,
                        guide_scale=guide_scale)
