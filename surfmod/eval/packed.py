"""Many B-spline nets in one set of flat arrays, so that one compiled call works through
the B-spline faces of a whole part.

Measuring a real part's mesh projects a few hundred to a few thousand samples per face
on a few hundred faces; one call per face costs tens of microseconds of Python and
dispatch, about as much as the arithmetic.  :func:`pack` lays every net's tables
(:class:`~surfmod.eval.local.LocalNet`) end to end with offsets, and the kernels here
slice them back, face by face, inside one compiled loop.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .kernels import binomials
from .projection_kernel import project_distances_compiled, wrap_parameter
from .scattered_compiled import scattered_compiled


class NetPack(NamedTuple):
    """Nets end to end: per net ``p``, ``q``, ``n``, ``m``, ``rational`` and the bucket
    origins/scales; flat ``knots_u``/``knots_v``/``ctrl``/``inv_u``/``inv_v`` and bucket
    tables with ``(F + 1,)`` offsets (``*_at``); ``lo``/``hi``/``period``/``periodic``
    ``(F, 2)``: how each surface maps its parameters (as OCCT evaluates it)."""

    p: np.ndarray
    q: np.ndarray
    n: np.ndarray
    m: np.ndarray
    rational: np.ndarray
    knots_u: np.ndarray
    knots_u_at: np.ndarray
    knots_v: np.ndarray
    knots_v_at: np.ndarray
    ctrl: np.ndarray
    ctrl_at: np.ndarray
    inv_u: np.ndarray
    inv_u_at: np.ndarray
    inv_v: np.ndarray
    inv_v_at: np.ndarray
    bucket_u_origin: np.ndarray
    bucket_u_scale: np.ndarray
    bucket_u: np.ndarray
    bucket_u_at: np.ndarray
    bucket_v_origin: np.ndarray
    bucket_v_scale: np.ndarray
    bucket_v: np.ndarray
    bucket_v_at: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    period: np.ndarray
    periodic: np.ndarray


def _flat(arrays: list, dtype) -> tuple[np.ndarray, np.ndarray]:
    """Arrays end to end (raveled) and their ``(F + 1,)`` start offsets."""
    sizes = [a.size for a in arrays]
    at = np.zeros(len(arrays) + 1, np.int64)
    np.cumsum(sizes, out=at[1:])
    flat = np.concatenate([a.ravel() for a in arrays]).astype(dtype, copy=False) if arrays else np.zeros(0, dtype)
    return flat, at


def pack(nets: list, lo, hi, period, periodic) -> NetPack:
    """One :class:`NetPack` of :class:`~surfmod.eval.local.LocalNet` s, with each
    surface's parameter map (``(F, 2)`` arrays-likes, see
    :func:`surfmod.eval.projection_kernel.project_distances_compiled`).

    >>> import numpy as np, surfmod as sm
    >>> from surfmod.gallery.synthetic import wavy_net
    >>> nets = [sm.BSplineSurface(wavy_net(5, 4), (3, 2))._local_net()] * 2
    >>> pk = pack(nets, [[0, 0]] * 2, [[1, 1]] * 2, [[0, 0]] * 2, [[False, False]] * 2)
    >>> pk.ctrl_at.tolist(), pk.p.tolist()
    ([0, 80, 160], [3, 3])
    """
    knots_u, knots_u_at = _flat([t.knots_u for t in nets], float)
    knots_v, knots_v_at = _flat([t.knots_v for t in nets], float)
    ctrl, ctrl_at = _flat([t.ctrl for t in nets], float)
    inv_u, inv_u_at = _flat([t.inv_u for t in nets], float)
    inv_v, inv_v_at = _flat([t.inv_v for t in nets], float)
    bucket_u, bucket_u_at = _flat([t.bucket_u[2] for t in nets], np.int64)
    bucket_v, bucket_v_at = _flat([t.bucket_v[2] for t in nets], np.int64)
    return NetPack(
        np.array([t.p for t in nets], np.int64), np.array([t.q for t in nets], np.int64),
        np.array([t.ctrl.shape[0] for t in nets], np.int64), np.array([t.ctrl.shape[1] for t in nets], np.int64),
        np.array([t.rational for t in nets], bool),
        knots_u, knots_u_at, knots_v, knots_v_at, ctrl, ctrl_at, inv_u, inv_u_at, inv_v, inv_v_at,
        np.array([t.bucket_u[0] for t in nets], float), np.array([t.bucket_u[1] for t in nets], float),
        bucket_u, bucket_u_at,
        np.array([t.bucket_v[0] for t in nets], float), np.array([t.bucket_v[1] for t in nets], float),
        bucket_v, bucket_v_at,
        np.asarray(lo, float).reshape(-1, 2), np.asarray(hi, float).reshape(-1, 2),
        np.asarray(period, float).reshape(-1, 2), np.asarray(periodic, bool).reshape(-1, 2),
    )


def project_segments(pk: NetPack, boxes: np.ndarray, points: np.ndarray, uv: np.ndarray, segments: np.ndarray,
                     start: np.ndarray, threshold: np.ndarray) -> np.ndarray:
    """Distance bounds of ``points (N, 3)`` from their nets, segment by segment:
    ``segments (S, 3)`` rows ``(net, first point, end point)``, each with its ``start``
    and ``threshold`` (``(S,)``; see :func:`surfmod.eval.projection_kernel.project_distances_compiled`)
    and its net's Gauss-Newton ``boxes[net]`` ``(u0, u1, v0, v1)``.  Returns ``(N,)``.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> s = sm.BSplineSurface(net, (3, 3))  # the square [0, 3]^2 in z = 0
    >>> pk = pack([s._local_net()], [[0, 0]], [[1, 1]], [[0, 0]], [[False, False]])
    >>> d = project_segments(pk, np.array([[0, 1, 0, 1.0]]), np.array([[1.0, 2.0, 0.25]]),
    ...                      np.array([[0.5, 0.5]]), np.array([[0, 0, 1]]), np.zeros(1), np.zeros(1))
    >>> round(float(d[0]), 12)  # from the guess (0.5, 0.5) down to the foot point
    0.25
    """
    out = np.zeros(len(points))
    _project_segments(pk, np.ascontiguousarray(boxes, float), np.ascontiguousarray(points, float),
                      np.ascontiguousarray(uv, float), np.ascontiguousarray(segments, np.int64),
                      np.ascontiguousarray(start, float), np.ascontiguousarray(threshold, float), out)
    return out


def triangle_deviations_compiled(pk: NetPack, boxes: np.ndarray, nodes: np.ndarray, uv: np.ndarray,
                                 triangles: np.ndarray, faces: np.ndarray, bary: np.ndarray,
                                 threshold: np.ndarray) -> np.ndarray:
    """Max distance bound per triangle over its barycentric samples ``bary (K, 3)``:
    each sample ``bary @ corners`` in space and in ``(u, v)`` (``nodes (N, 3)``, ``uv
    (N, 2)``, ``triangles (T, 3)`` indexing them), projected onto its net from its
    ``(u, v)`` while its bound exceeds its net's ``threshold`` (as
    :func:`surfmod.meshing.deviation.triangle_deviations`, its NumPy twin, with a projector).
    ``faces (F, 3)`` rows ``(net, first triangle, end triangle)``.  Returns ``(T,)``.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> net[1:3, 1:3, 2] = 1.0  # a bump
    >>> s = sm.BSplineSurface(net, (3, 3))
    >>> pk = pack([s._local_net()], [[0, 0]], [[1, 1]], [[0, 0]], [[False, False]])
    >>> uv = np.array([[0.2, 0.2], [0.8, 0.2], [0.5, 0.8]])
    >>> d = triangle_deviations_compiled(pk, np.array([[0, 1, 0, 1.0]]), s.points(uv[:, 0], uv[:, 1]), uv,
    ...                                  np.array([[0, 1, 2]]), np.array([[0, 0, 1]]), np.array([[1 / 3] * 3]),
    ...                                  np.zeros(1))
    >>> bool(0.0 < d[0] < 0.6)  # the chord sags below the bump's top
    True
    """
    out = np.zeros(len(triangles))
    _triangle_deviations(pk, np.ascontiguousarray(boxes, float), np.ascontiguousarray(nodes, float),
                         np.ascontiguousarray(uv, float), np.ascontiguousarray(triangles, np.int64),
                         np.ascontiguousarray(faces, np.int64), np.ascontiguousarray(bary, float),
                         np.ascontiguousarray(threshold, float), out)
    return out


def derivatives_segments(pk: NetPack, u: np.ndarray, v: np.ndarray, segments: np.ndarray, order: int) -> np.ndarray:
    """Partials to ``order`` ``(N, K, K, 3)`` at ``(u, v)`` pairs, segment by segment:
    ``segments (S, 3)`` rows ``(net, first point, end point)``; parameters are mapped
    as each surface maps them (periodic wrap, clamp) before evaluating.

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> s = sm.BSplineSurface(net, (3, 3))
    >>> pk = pack([s._local_net()], [[0, 0]], [[1, 1]], [[0, 0]], [[False, False]])
    >>> d = derivatives_segments(pk, [0.5, 1.7], [0.5, 0.5], np.array([[0, 0, 2]]), 1)
    >>> d[1, 0, 0].tolist()  # 1.7 clamped to the domain's end
    [3.0, 1.5, 0.0]
    """
    out = np.zeros((len(u), order + 1, order + 1, 3))
    _derivatives_segments(pk, np.ascontiguousarray(u, float), np.ascontiguousarray(v, float),
                          np.ascontiguousarray(segments, np.int64), int(order), binomials(order), out)
    return out


@njit(cache=True, inline="always")
def _net(pk, f):
    """Net ``f`` of a pack as the one-net kernels take it."""
    pf, qf, nf, mf = pk.p[f], pk.q[f], pk.n[f], pk.m[f]
    return (pk.knots_u[pk.knots_u_at[f]:pk.knots_u_at[f + 1]], pf, pk.knots_v[pk.knots_v_at[f]:pk.knots_v_at[f + 1]],
            qf, pk.ctrl[pk.ctrl_at[f]:pk.ctrl_at[f + 1]].reshape((nf, mf, 4)), pk.rational[f],
            pk.inv_u[pk.inv_u_at[f]:pk.inv_u_at[f + 1]].reshape((nf, pf + 1, pf + 1)),
            pk.inv_v[pk.inv_v_at[f]:pk.inv_v_at[f + 1]].reshape((mf, qf + 1, qf + 1)),
            (pk.bucket_u_origin[f], pk.bucket_u_scale[f], pk.bucket_u[pk.bucket_u_at[f]:pk.bucket_u_at[f + 1]]),
            (pk.bucket_v_origin[f], pk.bucket_v_scale[f], pk.bucket_v[pk.bucket_v_at[f]:pk.bucket_v_at[f + 1]]))


@njit(cache=True, error_model="numpy")
def _triangle_deviations(pk, boxes, nodes, uv, triangles, faces, bary, threshold, out):
    for r in range(faces.shape[0]):
        f, a, b = faces[r, 0], faces[r, 1], faces[r, 2]
        if a == b:
            continue
        ku, pf, kv, qf, net, rat, iu, iv, bu, bv = _net(pk, f)
        # the face's samples, then one projection call over them (a call per sample
        # would cost its arrays' reference counting every time)
        count = (b - a) * bary.shape[0]
        pts, guess, dist = np.empty((count, 3)), np.empty((count, 2)), np.empty(count)
        at = 0
        for t in range(a, b):
            i, j, k = triangles[t, 0], triangles[t, 1], triangles[t, 2]
            for s in range(bary.shape[0]):
                w0, w1, w2 = bary[s, 0], bary[s, 1], bary[s, 2]
                for c in range(3):
                    pts[at, c] = w0 * nodes[i, c] + w1 * nodes[j, c] + w2 * nodes[k, c]
                for c in range(2):
                    guess[at, c] = w0 * uv[i, c] + w1 * uv[j, c] + w2 * uv[k, c]
                at += 1
        project_distances_compiled(ku, pf, kv, qf, net, rat, iu, iv, bu, bv, pk.lo[f], pk.hi[f], pk.period[f],
                          pk.periodic[f], boxes[f], pts, guess, threshold[f], dist, threshold[f])
        at = 0
        for t in range(a, b):
            worst = 0.0
            for s in range(bary.shape[0]):
                worst = max(worst, dist[at])
                at += 1
            out[t] = worst


@njit(cache=True, error_model="numpy")
def _project_segments(pk, boxes, points, uv, segments, start, threshold, out):
    for s in range(segments.shape[0]):
        f, a, b = segments[s, 0], segments[s, 1], segments[s, 2]
        if a == b:
            continue
        ku, pf, kv, qf, net, rat, iu, iv, bu, bv = _net(pk, f)
        project_distances_compiled(ku, pf, kv, qf, net, rat, iu, iv, bu, bv, pk.lo[f], pk.hi[f], pk.period[f],
                          pk.periodic[f], boxes[f], points[a:b], uv[a:b], threshold[s], out[a:b], start[s])


@njit(cache=True, error_model="numpy")
def _derivatives_segments(pk, u, v, segments, order, binom, out):
    for s in range(segments.shape[0]):
        f, a, b = segments[s, 0], segments[s, 1], segments[s, 2]
        if a == b:
            continue
        ku, pf, kv, qf, net, rat, iu, iv, bu, bv = _net(pk, f)
        uu, vv = np.empty(b - a), np.empty(b - a)
        for i in range(b - a):
            uu[i] = wrap_parameter(u[a + i], pk.lo[f, 0], pk.hi[f, 0], pk.period[f, 0], pk.periodic[f, 0])
            vv[i] = wrap_parameter(v[a + i], pk.lo[f, 1], pk.hi[f, 1], pk.period[f, 1], pk.periodic[f, 1])
        scattered_compiled(ku, pf, kv, qf, net, uu, vv, order, rat, binom, iu, iv, bu, bv, out[a:b])
