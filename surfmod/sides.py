"""The four sides of a parameter rectangle and the G0/G1/G2 measure across a boundary, one
level below the constructs that build to a continuity (:mod:`surfmod.ops.blend`,
:mod:`surfmod.construct.fill`) and the operation that reports it
(:mod:`surfmod.ops.continuity`).  See :doc:`/guide/analysis`.

>>> import surfmod as sm, numpy as np
>>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
>>> [a.tolist() for a in side_params(s, "u1", np.array([0.0, 0.5]))]
[[1.0, 1.0], [0.0, 0.5]]
"""

from __future__ import annotations

import numpy as np

from .surface import Surface

#: side name -> (fixed parameter index: 0 = u fixed, 1 = v fixed; end: 0 low, 1 high)
SIDES = {"u0": (0, 0), "u1": (0, 1), "v0": (1, 0), "v1": (1, 1)}


# -- the measurement ------------------------------------------------------------------------------
def _unit(x):
    n = np.linalg.norm(x, axis=-1, keepdims=True)
    return x / np.where(n > 0, n, 1.0)


def _tangent_coords(ders, x):
    """``(a, b)`` with ``a Su + b Sv = x`` (x in the tangent plane), by the first form."""
    su, sv = ders[:, 1, 0], ders[:, 0, 1]
    e, f, g = (np.einsum("ij,ij->i", p, q) for p, q in ((su, su), (su, sv), (sv, sv)))
    rx, ry = np.einsum("ij,ij->i", su, x), np.einsum("ij,ij->i", sv, x)
    det = np.where(np.abs(e * g - f * f) > 0, e * g - f * f, np.finfo(float).tiny)
    return (g * rx - f * ry) / det, (e * ry - f * rx) / det


def normal_curvature(ders, normal, direction):
    """Normal curvature ``II(d, d) / I(d, d)`` of the surface in the tangent ``direction``."""
    a, b = _tangent_coords(ders, direction)
    second = ders[:, 2, 0] * (a * a)[:, None] + 2 * ders[:, 1, 1] * (a * b)[:, None] + ders[:, 0, 2] * (b * b)[:, None]
    first = ders[:, 1, 0] * a[:, None] + ders[:, 0, 1] * b[:, None]
    return np.einsum("ij,ij->i", second, normal) / np.maximum(np.einsum("ij,ij->i", first, first), np.finfo(float).tiny)


def measure(ders_a, inward_a, ders_b, inward_b, edge_tangent):
    """Per-sample ``(gap, angle, jump, k_a, k_b, flip)`` from order-2 derivative arrays
    ``(N, 3, 3, 3)`` of both surfaces, 3-D vectors pointing into each surface and the
    edge tangent (what is compared: :doc:`/guide/analysis`).  ``flip`` is -1 where
    ``b``'s normal had to be reversed to be oriented like ``a``'s."""
    gap = np.linalg.norm(ders_a[:, 0, 0] - ders_b[:, 0, 0], axis=1)
    n_a = _unit(np.cross(ders_a[:, 1, 0], ders_a[:, 0, 1]))
    n_b = _unit(np.cross(ders_b[:, 1, 0], ders_b[:, 0, 1]))

    def across(n, inward):
        e = _unit(edge_tangent - np.einsum("ij,ij->i", edge_tangent, n)[:, None] * n)
        t = inward - np.einsum("ij,ij->i", inward, e)[:, None] * e
        t = _unit(t - np.einsum("ij,ij->i", t, n)[:, None] * n)
        return e, t

    e_a, t_a = across(n_a, inward_a)
    e_b, t_b = across(n_b, inward_b)
    hand_a = np.sign(np.einsum("ij,ij->i", np.cross(e_a, t_a), n_a))
    hand_b = np.sign(np.einsum("ij,ij->i", np.cross(e_b, -t_b), n_b))
    flip = np.where(hand_a * hand_b < 0, -1.0, 1.0)
    n_b = n_b * flip[:, None]
    angle = np.arctan2(np.linalg.norm(np.cross(n_a, n_b), axis=1), np.einsum("ij,ij->i", n_a, n_b))
    k_a = normal_curvature(ders_a, n_a, t_a)
    k_b = normal_curvature(ders_b, n_b, t_b)
    return gap, angle, np.abs(k_a - k_b), k_a, k_b, flip


# -- boundaries of parameter rectangles -----------------------------------------------------------
def side_params(s: Surface, side: str, t: np.ndarray):
    """``(u, v)`` arrays of side ``side`` at free-parameter values ``t``."""
    fixed, end = SIDES[side]
    value = np.full_like(t, s.domain[fixed][end])
    return (value, t) if fixed == 0 else (t, value)


def side_vectors(s: Surface, side: str, ders):
    """Edge tangent (derivative along the side) and the inward cross derivative."""
    fixed, end = SIDES[side]
    along = ders[:, 0, 1] if fixed == 0 else ders[:, 1, 0]
    cross = ders[:, 1, 0] if fixed == 0 else ders[:, 0, 1]
    return along, cross if end == 0 else -cross
