"""Drop-cutter heights of a ball end mill on the exact faces, polished from the mesh's.

The mesh drop (:mod:`surfmod.uses.drop_cutter`) is exact for BRepMesh's triangles, which
are chords of the faces.  Where the ball touches a face inside its trim, the exact
cutter location satisfies: the ball centre ``c = (x, y, z + r)`` is the face point
``S(u, v)`` pushed out by ``r`` along the face's upward unit normal ``N``.  So ``(u, v)``
solves the two equations ``(S + r N)_xy(u, v) = (x, y)`` and the tip height is
``(S + r N)_z - r``.  Newton's method solves them for every location at once (per face,
vectorized), started from the projection of the mesh contact onto the face; the
Jacobian of ``S + r N`` comes from central differences of the exact evaluator (the
residual is exact, so Newton still converges to rounding).  A solution outside the
face's trim (the ball rests on an edge or a vertex, not the face's interior), on a face
seen from below, or that does not converge keeps the mesh height and is reported so.
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


def _offset_points(face, u, v, radius: float):
    """``S + r N`` with ``N`` the unit normal turned upwards, and ``S``."""
    d = face.derivatives(u, v, 1)
    n = np.cross(d[..., 1, 0, :], d[..., 0, 1, :])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    n *= np.where(n[..., 2:3] < 0, -1.0, 1.0)
    return d[..., 0, 0, :] + radius * n, d[..., 0, 0, :]


def polish_ball(face, xy: np.ndarray, contacts: np.ndarray, radius: float):
    """Exact tip heights ``(N,)`` of a ball of ``radius`` at ``xy`` ``(N, 2)`` touching
    the trimmed face ``face`` (a :class:`surfmod.TrimmedFace`) near ``contacts``
    ``(N, 3)``, the exact contact points ``(N, 3)``, and a mask ``(N,)`` of the
    locations where the exact contact lies inside the face (elsewhere NaN).

    >>> import surfmod as sm, build123d as bd, numpy as np
    >>> face = sm.from_face(bd.Sphere(5.0).faces()[0])
    >>> z, contact, ok = polish_ball(face, np.array([[1.0, 2.0]]), np.array([[1.0, 2.0, 4.5]]), 1.0)
    >>> bool(ok[0]), bool(abs(z[0] - (np.sqrt(36.0 - 5.0) - 1.0)) < 1e-12)
    (True, True)
    """
    (u0, u1), (v0, v1) = face.domain
    proj = project(contacts, face)
    u, v = proj.u.astype(float).copy(), proj.v.astype(float).copy()
    hu, hv = STEP * (u1 - u0), STEP * (v1 - v0)
    done = np.zeros(len(xy), bool)
    for _ in range(ITERATIONS):
        live = ~done
        if not live.any():
            break
        ul, vl = u[live], v[live]
        c, _ = _offset_points(face, ul, vl, radius)
        miss = c[:, :2] - xy[live]
        # the face's domain may end within a step: difference inward there
        up = np.clip(ul + hu, u0, u1) - ul
        um = ul - np.clip(ul - hu, u0, u1)
        vp = np.clip(vl + hv, v0, v1) - vl
        vm = vl - np.clip(vl - hv, v0, v1)
        cu = (_offset_points(face, ul + up, vl, radius)[0] - _offset_points(face, ul - um, vl, radius)[0]) / (up + um)[:, None]
        cv = (_offset_points(face, ul, vl + vp, radius)[0] - _offset_points(face, ul, vl - vm, radius)[0]) / (vp + vm)[:, None]
        a, b, cc, d = cu[:, 0], cv[:, 0], cu[:, 1], cv[:, 1]
        det = a * d - b * cc
        good = np.abs(det) > 0
        det = np.where(good, det, 1.0)
        du = (d * miss[:, 0] - b * miss[:, 1]) / det
        dv = (-cc * miss[:, 0] + a * miss[:, 1]) / det
        u[live] = np.clip(ul - np.where(good, du, 0.0), u0, u1)
        v[live] = np.clip(vl - np.where(good, dv, 0.0), v0, v1)
        converged = (np.linalg.norm(miss, axis=1) <= CONVERGED * radius) | ~good
        done[np.flatnonzero(live)[converged]] = True
    c, p = _offset_points(face, u, v, radius)
    # a normal that is level (a wall) cannot hold the ball from below
    on = (np.linalg.norm(c[:, :2] - xy, axis=1) <= 1e3 * CONVERGED * radius) & (c[:, 2] - p[:, 2] > 0)
    if on.any():
        on[on] = face.contains(u[on], v[on])
    return np.where(on, c[:, 2] - radius, np.nan), np.where(on[:, None], p, np.nan), on


def exact_ball_heights(faces, owner: np.ndarray, xy: np.ndarray, z: np.ndarray, contacts: np.ndarray,
                       touched: np.ndarray, radius: float):
    """Mesh heights ``z`` polished on the exact faces: ``faces`` (OCCT faces), ``owner``
    (face index of each mesh triangle), ``touched`` (triangle the ball rests on, -1 for
    none).  Returns the heights and a mask of the locations polished (the others keep
    their mesh height: the ball rests on an edge or vertex, or touches nothing), and the
    contact points (exact where polished)."""
    z = np.array(z, dtype=float)
    contacts = np.array(contacts, dtype=float)
    polished = np.zeros(len(z), bool)
    hit = touched >= 0
    face_of = np.where(hit, owner[np.where(hit, touched, 0)], -1)
    for k in np.unique(face_of[hit]):  # one vectorized solve per touched face
        rows = np.flatnonzero(face_of == k)
        exact, touch, on = polish_ball(from_face(faces[k]), xy[rows], contacts[rows], radius)
        z[rows[on]] = exact[on]
        contacts[rows[on]] = touch[on]
        polished[rows[on]] = True
    return z, contacts, polished
