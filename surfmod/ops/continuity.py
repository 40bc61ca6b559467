"""How well two surfaces meet along a shared boundary (:func:`continuity`): G0 gap, G1 normal
angle and the G2 jump of the normal curvature across the boundary, the second surface
oriented like the first.  See :doc:`/guide/analysis`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..readback import from_face, surface_of
from ..surface import Surface
from ..sides import SIDES, measure, side_params, side_vectors
from .project import closest_points

@dataclass(frozen=True)
class Continuity:
    """Continuity along a boundary (or, for a shell, along every shared edge).

    Maxima: ``g0`` (gap, model units), ``g1`` (normal angle, radians), ``g2`` (jump of
    the normal curvature across the boundary, 1/length) and ``g2_relative`` (``g2`` over
    the largest ``|k|`` on either side, or over 1/(boundary length) if that is larger,
    so that flat joins are judged on the scale of the part).  Per sample: ``points``, ``gap``, ``angle``,
    ``jump``, ``curvature_a``, ``curvature_b``, ``params_a``, ``params_b``; ``occt`` is
    OCCT's ``(C0Value, G1Angle, G2CurvatureGap)`` per sample when asked for;
    ``edges`` holds the per-edge results of a shell.

    >>> import surfmod as sm, numpy as np
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> net[..., 2] = 0.1 * net[..., 0] ** 2
    >>> a, b = sm.BSplineSurface(net).split(u=0.5)
    >>> c = sm.continuity(a, b)
    >>> c.label, bool(c.g0 < 1e-12 and c.g1 < 1e-12 and c.g2 < 1e-9)
    ('a.u1 | b.u0', True)
    """

    label: str
    points: np.ndarray
    gap: np.ndarray
    angle: np.ndarray
    jump: np.ndarray
    curvature_a: np.ndarray
    curvature_b: np.ndarray
    params_a: np.ndarray
    params_b: np.ndarray
    occt: np.ndarray | None = None
    edges: tuple = field(default=())

    @property
    def g0(self) -> float:
        return float(np.nanmax(self.gap)) if self.gap.size else 0.0

    @property
    def g1(self) -> float:
        return float(np.nanmax(self.angle)) if self.angle.size else 0.0

    @property
    def g2(self) -> float:
        return float(np.nanmax(self.jump)) if self.jump.size else 0.0

    @property
    def g2_relative(self) -> float:
        if not self.jump.size:
            return 0.0
        length = float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum()) if not self.edges else 0.0
        if self.edges:
            length = min(float(np.linalg.norm(np.diff(e.points, axis=0), axis=1).sum()) for e in self.edges)
        scale = max(float(np.nanmax(np.abs(self.curvature_a))), float(np.nanmax(np.abs(self.curvature_b))),
                    1.0 / length if length > 0 else 0.0)
        return self.g2 / scale if scale > 0 else self.g2

    def level(self, g0_tol: float = 1e-6, g1_tol: float = 1e-6, g2_tol: float = 1e-6) -> str:
        """``"G2"``, ``"G1"``, ``"G0"`` or ``"none"`` (``g2_tol`` is relative)."""
        if self.g0 > g0_tol:
            return "none"
        if self.g1 > g1_tol:
            return "G0"
        return "G2" if self.g2_relative <= g2_tol else "G1"

    def __str__(self) -> str:
        head = f"{'':<28} {'G0 gap':>10} {'G1 angle rad':>13} {'G2 jump':>10} {'G2 rel':>9}  level"
        lines = [f"continuity {self.label} ({self.gap.size} samples)", head, "-" * len(head)]
        rows = self.edges if self.edges else (self,)
        for r in rows:
            lines.append(f"{r.label:<28.28} {r.g0:>10.2e} {r.g1:>13.2e} {r.g2:>10.2e} {r.g2_relative:>9.2e}  {r.level()}")
        if self.edges:
            lines.append(f"{'max over ' + str(len(self.edges)) + ' edges':<28} {self.g0:>10.2e} {self.g1:>13.2e} "
                         f"{self.g2:>10.2e} {self.g2_relative:>9.2e}  {self.level()}")
        if self.occt is not None:
            o = np.nanmax(self.occt, axis=0)
            lines.append(f"{'OCCT LocalAnalysis (max)':<28} {o[0]:>10.2e} {o[1]:>13.2e} {o[2]:>10.2e} {'(gap)':>9}")
        return "\n".join(lines)


def _free_samples(s: Surface, side: str, count: int):
    return np.linspace(*s.domain[1 - SIDES[side][0]], count)


def _side_points(s, side, count):
    t = _free_samples(s, side, count)
    return t, s.points(*side_params(s, side, t))


def _size(s: Surface) -> float:
    """The largest extent of a 5 x 5 sample grid of ``s``: the scale of the tests below."""
    return max(np.ptp(s.grid(*(np.linspace(*d, 5) for d in s.domain)).reshape(-1, 3), axis=0).max(), 1e-300)


def _one_sided(p, q):
    """Largest distance from a point of ``p`` to the nearest point of ``q``."""
    return float(np.linalg.norm(p[:, None, :] - q[None, :, :], axis=2).min(axis=1).max())


def match_sides(a: Surface, b: Surface, probe: int = 41):
    """The pair of sides ``(side_a, side_b)`` such that the side of ``a`` lies closest
    along the side of ``b`` (sampled, then refined by exact closest points; the side of
    ``a`` may be a part of the side of ``b``; degenerate sides such as poles are skipped)
    and that distance."""
    size = _size(a)
    best = (np.inf, None, None)
    for sa in SIDES:
        _, pa = _side_points(a, sa, probe)
        if np.linalg.norm(pa[-1] - pa[0]) + np.linalg.norm(pa[probe // 2] - pa[0]) < 1e-9 * size:
            continue
        for sb in SIDES:
            _, pb = _side_points(b, sb, 4 * probe)
            d = _one_sided(pa, pb)
            if d < best[0]:
                best = (d, sa, sb)
    if best[1] is None:
        raise SurfmodError("b: no side of b runs along a side of a (give edge=(side_a, side_b))")
    _, sa, sb = best
    _, pa = _side_points(a, sa, probe)
    on_b = b.points(*side_params(b, sb, _closest_on_side(b, sb, pa)))
    exact = float(np.linalg.norm(on_b - pa, axis=1).max())
    if exact > 1e-3 * size:
        raise SurfmodError("b: no side of b runs along a side of a (give edge=(side_a, side_b))")
    return sa, sb, exact


def _closest_on_side(s: Surface, side: str, points: np.ndarray, iterations: int = 30):
    """Free parameter of the closest point on a side to each point (dense seed + Newton)."""
    seeds_t, seeds_p = _side_points(s, side, 512)
    t = seeds_t[np.argmin(np.linalg.norm(points[:, None] - seeds_p[None], axis=2), axis=1)]
    fixed = SIDES[side][0]
    lo, hi = s.domain[1 - fixed]
    for _ in range(iterations):
        d = s.derivatives(*side_params(s, side, t), order=2)
        c0 = d[:, 0, 0]
        c1 = d[:, 0, 1] if fixed == 0 else d[:, 1, 0]
        c2 = d[:, 0, 2] if fixed == 0 else d[:, 2, 0]
        diff = c0 - points
        f = np.einsum("ij,ij->i", diff, c1)
        fp = np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", diff, c2)
        step = f / np.where(np.abs(fp) > 0, fp, 1.0)
        t = np.clip(t - step, lo, hi)
        if np.all(np.abs(step) <= 1e-15 * max(1.0, hi - lo)):
            break
    return t


def _pair(a: Surface, b: Surface, side_a: str, side_b: str, samples: int, occt: bool, label: str):
    t_a = _free_samples(a, side_a, samples)
    ua, va = side_params(a, side_a, t_a)
    da = a.derivatives(ua, va, 2)
    pa = da[:, 0, 0]
    t_b = _closest_on_side(b, side_b, pa)
    ub, vb = side_params(b, side_b, t_b)
    db = b.derivatives(ub, vb, 2)
    along_a, in_a = side_vectors(a, side_a, da)
    _, in_b = side_vectors(b, side_b, db)
    return _result(label, a, (ua, va), da, in_a, b, (ub, vb), db, in_b, along_a, occt)


def _result(label, a, uv_a, da, in_a, b, uv_b, db, in_b, along, occt: bool) -> Continuity:
    """The measures of derivatives ``da``, ``db`` (order 2) at ``uv_a``, ``uv_b``, with
    the directions into each surface and along the boundary, and OCCT's when asked for."""
    gap, angle, jump, k_a, k_b, flip = measure(da, in_a, db, in_b, along)
    uv_a, uv_b = np.stack(uv_a, axis=1), np.stack(uv_b, axis=1)
    ref = None
    if occt:
        from ..occ.local_analysis import local_analysis

        ref = local_analysis(a.geom(), uv_a, b.geom(), uv_b, reverse_b=bool(np.median(flip) < 0))
    return Continuity(label, da[:, 0, 0], gap, angle, jump, k_a, k_b, uv_a, uv_b, ref)


def _projected(a: Surface, b: Surface, samples: int, occt: bool):
    """Fallback when no side of ``b`` runs along a side of ``a`` (e.g. ``b`` is a trimmed
    face such as OCCT's filling): the side of ``a`` lying on ``b`` is found by projecting
    its samples onto ``b``; ``b`` is taken to continue ``a`` across that side."""
    size = _size(a)
    best = (np.inf, None)
    for side in SIDES:
        _, pts = _side_points(a, side, 9)
        if np.linalg.norm(pts[-1] - pts[0]) + np.linalg.norm(pts[4] - pts[0]) < 1e-9 * size:
            continue
        d = float(closest_points(b, pts)[3].max())
        if d < best[0]:
            best = (d, side)
    if best[1] is None or best[0] > 0.05 * size:
        raise SurfmodError("b: no side of b runs along a side of a, nor does a side of a lie on b "
                           "(give edge=(side_a, side_b))")
    side_a = best[1]
    t_a = _free_samples(a, side_a, samples)
    ua, va = side_params(a, side_a, t_a)
    da = a.derivatives(ua, va, 2)
    ub, vb, _, _ = closest_points(b, da[:, 0, 0])
    db = b.derivatives(ub, vb, 2)
    along_a, in_a = side_vectors(a, side_a, da)
    return _result(f"a.{side_a} | b (projected)", a, (ua, va), da, in_a, b, (ub, vb), db, -in_a, along_a, occt)


# -- faces and shells -----------------------------------------------------------------------------
def _to_3d(ders, uv_vec):
    return ders[:, 1, 0] * uv_vec[:, :1] + ders[:, 0, 1] * uv_vec[:, 1:]


def _clip_uv(s: Surface, uv):
    (u0, u1), (v0, v1) = s.domain
    return np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)


def _edge_result(rec, surfaces, occt: bool, label: str):
    (sa, sb), (uva, uvb) = surfaces, rec["uv"]
    ua, va = _clip_uv(sa, uva)
    ub, vb = _clip_uv(sb, uvb)
    da, db = sa.derivatives(ua, va, 2), sb.derivatives(ub, vb, 2)
    return _result(label, sa, (ua, va), da, _to_3d(da, rec["inward"][0]), sb, (ub, vb), db,
                   _to_3d(db, rec["inward"][1]), _to_3d(da, rec["tangent"][0]), occt)


def _combined(label, parts):
    def cat(name):
        return np.concatenate([getattr(p, name) for p in parts]) if parts else np.empty((0,))

    occt = None
    if parts and all(p.occt is not None for p in parts):
        occt = np.concatenate([p.occt for p in parts])
    empty2 = np.empty((0, 2))
    return Continuity(
        label, cat("points") if parts else np.empty((0, 3)), cat("gap"), cat("angle"), cat("jump"),
        cat("curvature_a"), cat("curvature_b"), cat("params_a") if parts else empty2,
        cat("params_b") if parts else empty2, occt, tuple(parts))


def _shell(shape, samples: int, occt: bool, only_faces=None):
    from ..occ.local_analysis import shared_edges

    records = shared_edges(shape, samples)
    cache: dict = {}
    parts = []
    for rec in records:
        if only_faces is not None and sorted(rec["faces"]) != sorted(only_faces):
            continue
        surfaces = []
        for idx, face in zip(rec["faces"], rec["face_shapes"]):
            if idx not in cache:
                try:
                    cache[idx] = from_face(face)
                except SurfmodError:  # a surface type surfmod cannot read: its edges are left out
                    cache[idx] = None
            surfaces.append(cache[idx])
        if any(s is None for s in surfaces):
            continue
        fa, fb = rec["faces"]
        parts.append(_edge_result(rec, surfaces, occt, f"edge {rec['edge']}: face {fa} | face {fb}"))
    return parts


def _is_shape(obj) -> bool:
    from ..occ.topo import wrapped

    return not isinstance(obj, Surface) and wrapped(obj) is not None


def continuity(a, b=None, samples: int = 50, *, edge=None, occt: bool = False) -> Continuity:
    """G0 / G1 / G2 continuity along the boundary shared by ``a`` and ``b``.

    ``a``, ``b``: surfmod surfaces (the shared side is matched automatically, or given as
    ``edge=(side_a, side_b)`` with sides ``"u0"``, ``"u1"``, ``"v0"``, ``"v1"``), or two
    faces sharing an edge (sampled through the p-curves).  With ``b=None``, ``a`` is a
    shell or solid and every edge between two faces is reported (``result.edges``).
    ``occt=True`` also runs OCCT's ``LocalAnalysis_SurfaceContinuity`` at the same
    parameter pairs (``result.occt``).

    >>> import surfmod as sm
    >>> R = 2.0
    >>> cyl = sm.CylindricalSurface(R, u_range=(0, 1.5), v_range=(0, 3))
    >>> flat = sm.plane((R, 0, 0), (R, 0, 3), (R, -2, 0))   # tangent along the line u = 0
    >>> c = sm.continuity(cyl, flat)
    >>> round(c.g1, 12), round(c.g2, 12)       # G1, curvature jump exactly 1/R
    (0.0, 0.5)
    """
    samples = checks.count(samples, "samples", minimum=2)
    if b is None:
        if isinstance(a, Surface) or not _is_shape(a):
            raise SurfmodError("a: with b=None, a must be a shell, solid or other shape with several faces")
        parts = _shell(a, samples, occt)
        return _combined(f"shell ({len(parts)} edges)", parts)
    if not isinstance(a, Surface) and not isinstance(b, Surface) and _is_shape(a) and _is_shape(b):
        from ..occ.topo import compound, wrapped

        parts = _shell(compound([wrapped(a), wrapped(b)]), samples, occt, only_faces=(0, 1))
        if len(parts) == 1:
            return replace(parts[0], label="face a | face b")
        if parts:
            return _combined("face a | face b", parts)
    a = surface_of(a, "a")
    b = surface_of(b, "b")
    if edge is None:
        return _matched(a, b, samples, occt)
    try:
        side_a, side_b = edge
    except (TypeError, ValueError):
        raise SurfmodError(f"edge: expected (side_a, side_b), got {edge!r}") from None
    for name, side in (("edge[0]", side_a), ("edge[1]", side_b)):
        if side not in SIDES:
            raise SurfmodError(f"{name}: side must be one of u0, u1, v0, v1, got {side!r}")
    return _pair(a, b, side_a, side_b, samples, occt, f"a.{side_a} | b.{side_b}")


def _matched(a: Surface, b: Surface, samples: int, occt: bool) -> Continuity:
    """Continuity along the side pair found automatically.  The shorter side is the one
    sampled: when a side of ``b`` covers only part of a side of ``a`` (a 3- or 5-sided
    fill against its neighbour), the pair is measured from ``b`` and reported from ``a``'s
    point of view, so the argument order does not matter."""
    try:
        side_a, side_b, _ = match_sides(a, b)
        return _pair(a, b, side_a, side_b, samples, occt, f"a.{side_a} | b.{side_b}")
    except SurfmodError:
        pass
    try:
        side_b, side_a, _ = match_sides(b, a)
    except SurfmodError:
        return _projected(a, b, samples, occt)
    r = _pair(b, a, side_b, side_a, samples, occt, "")
    # r's curvatures are signed by b's normal; report them signed by a's, as _pair does
    n_a, n_b = a.normals(*r.params_b.T), b.normals(*r.params_a.T)
    sign = np.where(np.einsum("ij,ij->i", n_a, n_b) < 0, -1.0, 1.0)
    return Continuity(f"a.{side_a} | b.{side_b}", r.points, r.gap, r.angle, r.jump, sign * r.curvature_b,
                      sign * r.curvature_a, r.params_b, r.params_a, r.occt)


