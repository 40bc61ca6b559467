"""Curve tracing on the NumPy evaluator (:func:`newton`, :func:`trace`): the shared engine of
surface–surface and surface–plane intersection and of silhouette curves.

A problem's ``evaluate(X)`` returns, for flat ``(N, n)`` parameters, ``F (N, n-1)``, the
Jacobian ``J (N, n-1, n)``, the 3-D point ``P (N, 3)`` and ``dP/dx (N, 3, n)``.
See :doc:`/guide/surfaces` (section "Intersections and shadows").
"""

from __future__ import annotations

import numpy as np


def _solve(A, b):
    try:
        return np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.einsum("nij,nj->ni", np.linalg.pinv(A), b)


def newton(problem, X, C=None, d=None, iterations: int = 30, ftol: float = 1e-13, full: bool = False):
    """Vectorized Newton on ``[F(x); C.x - d] = 0`` (``C`` None: a square system).

    Returns ``(X, residual, converged)``; ``residual`` is ``|F|`` (model units).  With
    ``full`` the evaluation ``(F, J, P, dP)`` at the result is appended."""
    lo, hi = problem.lo, problem.hi
    X = np.clip(np.array(X, dtype=float), lo, hi)
    scale = problem.scale
    span = problem.span
    done = np.zeros(len(X), bool)
    for _ in range(iterations):
        idx = np.nonzero(~done)[0]
        if idx.size == 0:
            break
        x = X[idx]
        F, J, _, _ = problem.evaluate(x)
        if C is not None:
            F = np.concatenate([F, (np.einsum("ij,ij->i", C[idx], x) - d[idx])[:, None]], axis=1)
            J = np.concatenate([J, C[idx][:, None, :]], axis=1)
        dx = _solve(J, -F)
        dx = np.clip(dx, -0.5 * span, 0.5 * span)
        xn = np.clip(x + dx, lo, hi)
        X[idx] = xn
        # quadratic convergence: after a step below 1e-8 of the span the error is ~1e-16
        small = np.all(np.abs(xn - x) <= 1e-8 * span + 1e-300, axis=1)
        done[idx] = small
    ev = problem.evaluate(X)
    res = np.linalg.norm(ev[0], axis=1)
    if C is not None:
        res = np.maximum(res, np.abs(np.einsum("ij,ij->i", C, X) - d) * scale)
    ok = res <= max(ftol * scale, problem.tolerance)
    return (X, res, ok, ev) if full else (X, res, ok)


def tangent(problem, X, ev=None):
    """Unit null vectors ``(N, n)`` of the Jacobians and the 3-D tangents ``(N, 3)``."""
    _, J, _, dP = problem.evaluate(X) if ev is None else ev
    t = np.linalg.svd(J)[2][:, -1, :]
    t3 = np.einsum("nij,nj->ni", dP, t)
    return t, t3


def _inside(problem, x):
    return bool(np.all(x >= problem.lo) and np.all(x <= problem.hi))


def _boundary_end(problem, x, xp):
    """The exit point on the box boundary between ``x`` (inside) and ``xp`` (outside)."""
    lo, hi = problem.lo, problem.hi
    dx = xp - x
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(xp > hi, (hi - x) / dx, np.where(xp < lo, (lo - x) / dx, np.inf))
    for j in np.argsort(frac):
        if not np.isfinite(frac[j]):
            break
        bound = hi[j] if xp[j] > hi[j] else lo[j]
        c = np.zeros_like(x)
        c[j] = 1.0
        start = x + max(frac[j], 0.0) * dx
        xe, _, ok = newton(problem, start[None], c[None], np.array([bound]))
        if ok[0] and abs(xe[0, j] - bound) <= 1e-12 * problem.span[j]:
            return xe[0]
    return None


def trace(problem, x0, h: float, max_angle: float, max_points: int = 20000):
    """March both ways from the seed ``x0``.  Returns ``(X (N, n), closed)``."""
    hmin = h * 1e-6
    branches = []
    closed = False
    ev0 = problem.evaluate(x0[None])
    p0 = ev0[2][0]
    t0, t30 = tangent(problem, x0[None], ev0)
    for sign in (1.0, -1.0):
        pts = [x0]
        t, t3, px = sign * t0[0], sign * t30[0], p0
        step = h
        while len(pts) < max_points:
            x = pts[-1]
            speed = np.linalg.norm(t3)
            if speed <= 1e-300:
                break
            xp = x + (step / speed) * t
            if not _inside(problem, xp):
                xe = _boundary_end(problem, x, xp)
                if xe is not None and np.linalg.norm((xe - x) / problem.span) > 1e-12:
                    if step > hmin and np.linalg.norm(problem.evaluate(xe[None])[2][0] - px) > 1.5 * step:
                        step /= 2
                        continue
                    pts.append(xe)
                elif xe is None and step > hmin:
                    step /= 2
                    continue
                break
            xc, _, ok, ev = newton(problem, xp[None], t[None], np.array([t @ xp]), full=True)
            xc = xc[0]
            if not ok[0]:
                if step <= hmin:
                    break
                step /= 2
                continue
            t1, t31 = tangent(problem, xc[None], ev)
            t1, t31 = t1[0], t31[0]
            if t1 @ t < 0:
                t1, t31 = -t1, -t31
            cos = t3 @ t31 / (np.linalg.norm(t3) * np.linalg.norm(t31) + 1e-300)
            angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
            if angle > max_angle and step > hmin:
                step /= 2
                continue
            pc = ev[2][0]
            # closing: the start lies ahead within this step
            if len(pts) >= 3:
                to_start = p0 - px
                if np.linalg.norm(to_start) <= 1.05 * np.linalg.norm(pc - px) and to_start @ t3 > 0:
                    pts.append(x0)
                    closed = True
                    break
            pts.append(xc)
            t, t3, px = t1, t31, pc
            if angle < max_angle / 3:
                step = min(step * 1.5, h)
        branches.append(np.array(pts))
        if closed:
            break
    if closed:
        return branches[0], True
    back, fwd = branches
    X = np.concatenate([back[::-1], fwd[1:]])
    # on a periodic surface a loop leaves through the seam and comes back through it:
    # both ends lie on the domain boundary at one point in space
    ends = problem.evaluate(X[[0, -1]])[2]
    seam_loop = len(X) > 3 and np.linalg.norm(ends[0] - ends[1]) <= 10 * problem.tolerance
    return X, bool(seam_loop)


def segment_distances(points, polyline):
    """Distance from each point ``(N, 3)`` to a polyline ``(M, 3)``."""
    a, b = polyline[:-1], polyline[1:]
    if len(a) == 0:
        return np.linalg.norm(points - polyline[0], axis=1)
    ab = b - a
    denom = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("nij,ij->ni", points[:, None, :] - a[None], ab) / denom, 0, 1)
    proj = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - proj, axis=2).min(axis=1)


def trace_all(problem, seeds, h: float, max_angle: float, bar=None):
    """Trace a curve from every seed not already on a traced curve; ``bar`` (a tqdm bar
    or None) advances by the seeds each traced curve settles.

    Returns a list of ``(X, closed)``."""
    if len(seeds) == 0:
        return []
    seed_pts = problem.evaluate(seeds)[2]
    remaining = np.ones(len(seeds), bool)
    curves = []
    while np.any(remaining):
        i = int(np.nonzero(remaining)[0][0])
        X, closed = trace(problem, seeds[i], h, max_angle)
        remaining[i] = False
        P = problem.evaluate(X)[2]
        if len(X) >= 2:
            curves.append((X, closed))
        idx = np.nonzero(remaining)[0]
        if idx.size:
            near = segment_distances(seed_pts[idx], P) <= 0.05 * h + 10 * problem.tolerance
            remaining[idx[near]] = False
        if bar is not None:
            bar.update(len(seeds) - int(remaining.sum()) - bar.n)
    return curves
