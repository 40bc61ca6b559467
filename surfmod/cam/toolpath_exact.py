"""Drop-cutter heights on the exact faces, polished from the mesh's by Newton's method over
each face's own evaluator (ball, flat and bull nose: one set of equations, the ball and the
flat end its limits).

A solution outside the face's trim, on a face seen from below, or one that does not
converge keeps the mesh height and is reported so.  See :doc:`/guide/cam` (section "Exact
heights").
"""

from __future__ import annotations

import numpy as np

from ..ops.project import project
from ..readback import from_face

#: Newton iterations per location (quadratic convergence from the mesh contact: 3-5 used).
ITERATIONS = 30
#: Converged when the horizontal miss of the ball centre is below this share of the radius.
CONVERGED = 1e-13
#: Central-difference step for the Jacobian, as a share of the face's parameter span.
STEP = 1e-6


def _frames(face, u, v):
    """``S`` and the unit normal ``N`` turned upwards."""
    d = face.derivatives(u, v, 1)
    n = np.cross(d[..., 1, 0, :], d[..., 0, 1, :])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    n *= np.where(n[..., 2:3] < 0, -1.0, 1.0)
    return d[..., 0, 0, :], n


def _torus_axis(face, u, v, radius: float, corner: float):
    """``(S + c N)_xy + a N_xy / |N_xy|``: the axis of a bull nose whose torus touches the
    face at ``(u, v)``."""
    s, n = _frames(face, u, v)
    level = np.linalg.norm(n[..., :2], axis=-1, keepdims=True)
    return (s + corner * n)[..., :2] + (radius - corner) * n[..., :2] / np.where(level > 0, level, 1.0)


def _slope(face, u, v, radius: float):
    """``N_xy``: zero at a summit, where a flat bottom rests."""
    return _frames(face, u, v)[1][..., :2]


def _solve(face, point, target: np.ndarray, u: np.ndarray, v: np.ndarray, radius: float, scale: float):
    """Newton on ``point(face, u, v, radius) = target`` ``(N, 2)`` from ``(u, v)``, kept
    in the face's domain; returns ``(u, v)`` and a mask of the converged locations (miss
    within ``1e3 CONVERGED scale``)."""
    (u0, u1), (v0, v1) = face.domain
    u, v = u.copy(), v.copy()
    hu, hv = STEP * (u1 - u0), STEP * (v1 - v0)
    done = np.zeros(len(target), bool)
    for _ in range(ITERATIONS):
        live = ~done
        if not live.any():
            break
        ul, vl = u[live], v[live]
        miss = point(face, ul, vl, radius) - target[live]
        # the face's domain may end within a step: difference inward there
        up = np.clip(ul + hu, u0, u1) - ul
        um = ul - np.clip(ul - hu, u0, u1)
        vp = np.clip(vl + hv, v0, v1) - vl
        vm = vl - np.clip(vl - hv, v0, v1)
        cu = (point(face, ul + up, vl, radius) - point(face, ul - um, vl, radius)) / (up + um)[:, None]
        cv = (point(face, ul, vl + vp, radius) - point(face, ul, vl - vm, radius)) / (vp + vm)[:, None]
        a, b, cc, d = cu[:, 0], cv[:, 0], cu[:, 1], cv[:, 1]
        det = a * d - b * cc
        good = np.abs(det) > 0
        det = np.where(good, det, 1.0)
        du = (d * miss[:, 0] - b * miss[:, 1]) / det
        dv = (-cc * miss[:, 0] + a * miss[:, 1]) / det
        u[live] = np.clip(ul - np.where(good, du, 0.0), u0, u1)
        v[live] = np.clip(vl - np.where(good, dv, 0.0), v0, v1)
        converged = (np.linalg.norm(miss, axis=1) <= CONVERGED * scale) | ~good
        done[np.flatnonzero(live)[converged]] = True
    hit = np.linalg.norm(point(face, u, v, radius) - target, axis=1) <= 1e3 * CONVERGED * scale
    return u, v, hit


def _start(face, contacts: np.ndarray):
    proj = project(contacts, face)
    return proj.u.astype(float), proj.v.astype(float)


def polish(face, xy: np.ndarray, contacts: np.ndarray, radius: float, corner: float):
    """Exact tip heights ``(N,)`` of an end mill of ``radius`` and ``corner`` radius
    (``radius`` for a ball, 0 for a flat end) at ``xy`` ``(N, 2)`` touching the trimmed
    face ``face`` (a :class:`surfmod.TrimmedFace`) near ``contacts`` ``(N, 3)``, the exact
    contact points ``(N, 3)``, and a mask ``(N,)`` of the locations where the exact
    contact lies inside the face (elsewhere NaN): the rounded end's contact where the
    mesh contact lies on it (a ball's everywhere, a flat end's rim), the core's (a
    summit) where it lies within the flat core.

    >>> import surfmod as sm, build123d as bd, numpy as np
    >>> face = sm.from_face(bd.Sphere(5.0).faces()[0])
    >>> z, contact, ok = polish(face, np.array([[3.0, 0.0]]), np.array([[2.0, 0.0, 4.58]]), 1.0, 0.5)
    >>> # the tube centre on the sphere of radius 5.5 at x = 3 - 0.5: tip = sqrt(5.5² - 2.5²) - 0.5
    >>> bool(ok[0]), bool(abs(z[0] - (np.sqrt(5.5**2 - 2.5**2) - 0.5)) < 1e-12)
    (True, True)
    >>> z, contact, ok = polish(face, np.array([[1.0, 2.0]]), np.array([[1.0, 2.0, 4.5]]), 1.0, 1.0)  # a ball
    >>> bool(ok[0]), bool(abs(z[0] - (np.sqrt(36.0 - 5.0) - 1.0)) < 1e-12)
    (True, True)
    >>> z, contact, ok = polish(face, np.array([[3.0, 0.0]]), np.array([[2.0, 0.0, 4.58]]), 1.0, 0.0)  # a flat end
    >>> bool(ok[0]), bool(abs(z[0] - np.sqrt(25.0 - 4.0)) < 1e-12)
    (True, True)
    """
    core = radius - corner
    u, v = _start(face, contacts)
    z, touch = np.full(len(xy), np.nan), np.full((len(xy), 3), np.nan)
    on = np.zeros(len(xy), bool)
    torus = np.linalg.norm(contacts[:, :2] - xy, axis=1) >= core * (1.0 - 1e-6)
    rows = np.flatnonzero(torus)
    if rows.size:

        def axis(face, u, v, r):
            return _torus_axis(face, u, v, r, corner)

        ur, vr, hit = _solve(face, axis, xy[rows], u[rows], v[rows], radius, radius)
        p, n = _frames(face, ur, vr)
        # a level normal (a wall) cannot hold the end from below, nor (but for a ball, whose
        # contact needs no uphill direction) one at a summit
        hit &= (n[:, 2] > 0) & ((np.linalg.norm(n[:, :2], axis=1) > 0) | (core == 0.0))
        z[rows], touch[rows], on[rows] = _inside(face, ur, vr, hit, p[:, 2] + corner * n[:, 2] - corner, p)
    rows = np.flatnonzero(~torus)
    if rows.size:  # the core on a summit
        ur, vr, hit = _solve(face, _slope, np.zeros((rows.size, 2)), u[rows], v[rows], radius, 1.0)
        p = _frames(face, ur, vr)[0]
        hit &= np.linalg.norm(p[:, :2] - xy[rows], axis=1) <= core
        z[rows], touch[rows], on[rows] = _inside(face, ur, vr, hit, p[:, 2], p)
    return z, touch, on


def _inside(face, u, v, on, z, p):
    """Heights and contacts where ``on`` and the contact lies inside the face's trim."""
    on = on.copy()
    if on.any():
        on[on] = face.contains(u[on], v[on])
    return np.where(on, z, np.nan), np.where(on[:, None], p, np.nan), on


def exact_heights(faces, owner: np.ndarray, xy: np.ndarray, z: np.ndarray, contacts: np.ndarray,
                  touched: np.ndarray, radius: float, corner: float):
    """Mesh heights ``z`` of an end mill of ``radius`` and ``corner`` radius (see
    :func:`polish`) polished on the exact faces: ``faces`` (OCCT faces), ``owner`` (face
    index of each mesh triangle), ``touched`` (triangle the tool rests on, -1 for none).
    Returns the heights, the contact points (exact where polished) and a mask of the
    locations polished (the others keep their mesh height: the tool rests on an edge or
    vertex, or touches nothing)."""
    z = np.array(z, dtype=float)
    contacts = np.array(contacts, dtype=float)
    polished = np.zeros(len(z), bool)
    hit = touched >= 0
    face_of = np.where(hit, owner[np.where(hit, touched, 0)], -1)
    for k in np.unique(face_of[hit]):  # one vectorized solve per touched face
        rows = np.flatnonzero(face_of == k)
        exact, touch, on = polish(from_face(faces[k]), xy[rows], contacts[rows], radius, corner)
        z[rows[on]] = exact[on]
        contacts[rows[on]] = touch[on]
        polished[rows[on]] = True
    return z, contacts, polished
