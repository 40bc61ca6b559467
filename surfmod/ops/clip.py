"""Faces in the operations that take surfaces: intersections clipped to the face's
boundary, closest points on the face (boundary included) instead of on its untrimmed
surface.  Used at the entry of :func:`surfmod.intersect` and :func:`surfmod.project`."""

from __future__ import annotations

import numpy as np

from .closest import closest_points
from ..surface import Surface
from ..readback.trimmed import TrimmedFace, from_face


def as_face_surface(value):
    """A build123d ``Face`` or ``TopoDS_Face`` becomes its :class:`TrimmedFace`; anything
    else is returned unchanged."""
    if isinstance(value, Surface):
        return value
    shape = getattr(value, "wrapped", value)
    if type(shape).__name__ in ("TopoDS_Face", "TopoDS_Shape") and hasattr(shape, "ShapeType"):
        from ..occ.topo import wrapped

        s = wrapped(value)
        if s is not None and not s.IsNull() and s.ShapeType().name == "TopAbs_FACE":
            return from_face(value)
    return value


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[(start, stop), ...]`` of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]))


def _on_faces(a, b, uv_a, uv_b) -> np.ndarray:
    keep = np.ones(len(uv_a), dtype=bool)
    if isinstance(a, TrimmedFace):
        keep &= a.contains(uv_a[:, 0], uv_a[:, 1])
    if isinstance(b, TrimmedFace):
        keep &= b.contains(uv_b[:, 0], uv_b[:, 1])
    return keep


def _crossing(c, a, b, i_in: int, i_out: int, steps: int = 40):
    """Where the curve leaves the faces between samples ``i_in`` (on) and ``i_out`` (off):
    bisection on the chord, the point and parameters interpolated along it."""
    lo, hi = 0.0, 1.0
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        uv_a = c.uv_a[i_in] + mid * (c.uv_a[i_out] - c.uv_a[i_in])
        uv_b = c.uv_b[i_in] + mid * (c.uv_b[i_out] - c.uv_b[i_in])
        if _on_faces(a, b, uv_a[None], uv_b[None])[0]:
            lo = mid
        else:
            hi = mid
    lerp = lambda x: x[i_in] + lo * (x[i_out] - x[i_in])  # noqa: E731
    return lerp(c.points), lerp(c.uv_a), lerp(c.uv_b), c.tangents[i_in]


def clip_curves(curves, a, b, make):
    """Keep the parts of intersection curves lying on every :class:`TrimmedFace` operand
    (``uv_a`` on ``a``, ``uv_b`` on ``b``), each piece ending where the curve crosses the
    face boundary (bisection between the samples on either side);
    ``make(points, uv_a, uv_b, tangents, closed)`` builds a piece.  A closed curve cut
    open becomes open pieces."""
    out = []
    for c in curves:
        keep = _on_faces(a, b, c.uv_a, c.uv_b)
        if keep.all():
            out.append(c)
            continue
        n = len(keep)
        for i0, i1 in _runs(keep):
            cols = [c.points[i0:i1], c.uv_a[i0:i1], c.uv_b[i0:i1], c.tangents[i0:i1]]
            if i0 > 0:
                ends = _crossing(c, a, b, i0, i0 - 1)
                cols = [np.concatenate([e[None], col]) for e, col in zip(ends, cols)]
            if i1 < n:
                ends = _crossing(c, a, b, i1 - 1, i1)
                cols = [np.concatenate([col, e[None]]) for e, col in zip(ends, cols)]
            if len(cols[0]) >= 2:
                out.append(make(*cols, False))
    return out


def project_on_face(face: TrimmedFace, points: np.ndarray, u, v, p, d):
    """Closest points on a trimmed face: where the untrimmed closest point ``(u, v)``
    lies outside the face, the face's own closest point (``BRepExtrema_DistShapeShape``,
    boundary and interior minima alike) replaces it."""
    from ..occ.topo import closest_on_face

    outside = ~face.contains(u, v)
    if not outside.any():
        return u, v, p, d
    u, v, p, d = (np.array(x, dtype=float, copy=True) for x in (u, v, p, d))
    dist, near = closest_on_face(face.face_shape, points[outside])
    uu, vv, _, _ = closest_points(face, near)
    u[outside], v[outside], p[outside], d[outside] = uu, vv, near, dist
    return u, v, p, d
