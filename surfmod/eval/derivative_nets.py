"""Derivative control nets (The NURBS Book, eq. 3.8 and A3.3 applied in u and in v): the
partial d^(k+l) S / du^k dv^l of a B-spline net is a B-spline net of degrees
``(p - k, q - l)`` whose poles are scaled differences of neighbouring poles.

The form that keeps the digits on crowded knots, where the usual sum of basis derivatives
cancels; :mod:`surfmod.eval.local` takes it for nets whose spans differ by more than
:data:`CROWDED`.  See :doc:`/design_eval` (section "Where the precision is kept").

>>> import numpy as np
>>> knots = np.array([0, 0, 0, 1, 1, 1.0])
>>> nets = derivative_nets(knots, 2, knots, 2, np.arange(27.0).reshape(3, 3, 3), 1)
>>> sorted(nets), nets[1, 0][0].tolist(), nets[1, 0][1]
([(0, 1), (1, 0), (1, 1)], [0.0, 0.0, 1.0, 1.0], 1)
>>> nets[1, 0][4][:, 0].tolist()  # 2 (P[i + 1] - P[i]) / 1 along u
[[18.0, 18.0, 18.0], [18.0, 18.0, 18.0]]
"""

from __future__ import annotations

import numpy as np

from . import tensor

#: a net whose longest non-empty knot span (in u or in v) is more than this many times
#: its shortest takes its partials from the derivative nets: the usual sum's rounding
#: grows about with this ratio, so below it the usual sum (one evaluation, where the
#: derivative nets take (order + 1)^2) loses at most three of the sixteen digits
CROWDED = 1e3


def crowded(knots_u, p: int, knots_v, q: int) -> bool:
    """Whether the knot spans of either direction differ by more than :data:`CROWDED`.

    >>> import numpy as np
    >>> crowded(np.array([0, 0, 1e-5, 1, 1.0]), 1, np.array([0, 0, 1, 1.0]), 1)
    True
    """
    return any(_span_ratio(k, d) > CROWDED for k, d in ((knots_u, p), (knots_v, q)))


def _span_ratio(knots, degree: int) -> float:
    """Longest over shortest non-empty span of the domain (1 for a single span)."""
    gaps = np.diff(np.asarray(knots, float)[degree:len(knots) - degree])
    gaps = gaps[gaps > 0]
    return float(gaps.max() / gaps.min()) if gaps.size else 1.0


def differenced(knots, degree: int, ctrl: np.ndarray, axis: int, differences=None):
    """One derivative along ``axis`` (0: u, 1: v) of the net ``ctrl`` (``(n, m, d)``) of
    ``degree`` on ``knots``: ``(knots[1:-1], degree - 1, poles)`` with poles
    ``degree (P[i + 1] - P[i]) / (knots[i + degree + 1] - knots[i + 1])`` (eq. 3.8); a
    pole whose knot difference is zero (a knot repeated more than the new degree allows)
    lies under a basis function that is zero everywhere and is set to 0.
    ``differences``: ``P[i + 1] - P[i]`` formed by the caller (see :func:`homogeneous_differences`)."""
    c = np.moveaxis(ctrl, axis, 0)
    n = c.shape[0]
    span = knots[degree + 1:degree + n] - knots[1:n]
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(span > 0, degree / span, 0.0)
    steps = c[1:] - c[:-1] if differences is None else np.moveaxis(differences, axis, 0)
    poles = steps * scale.reshape((-1,) + (1,) * (c.ndim - 1))
    return knots[1:-1], degree - 1, np.ascontiguousarray(np.moveaxis(poles, 0, axis))


def homogeneous_differences(points, weights, centre, axis: int) -> np.ndarray:
    """Differences of neighbouring poles along ``axis`` of the homogeneous net
    ``(w (P - centre), w)`` formed from the Cartesian poles, as
    ``w[i + 1] (P[i + 1] - P[i]) + (w[i + 1] - w[i]) (P[i] - centre)``: exact where the
    weights are equal, where the difference of two rounded products ``w P`` would keep
    their rounding (the weights of a revolved or conic face vary along one direction only)."""
    pts = np.moveaxis(np.asarray(points, float), axis, 0)
    w = np.moveaxis(np.asarray(weights, float), axis, 0)[..., None]
    dw = w[1:] - w[:-1]
    xyz = w[1:] * (pts[1:] - pts[:-1]) + dw * (pts[:-1] - centre)
    return np.moveaxis(np.concatenate([xyz, dw], axis=-1), 0, axis)


def derivative_nets(knots_u, p: int, knots_v, q: int, ctrl: np.ndarray, order: int, cartesian=None) -> dict:
    """``{(k, l): (knots_u', p - k, knots_v', q - l, poles)}`` for every partial
    ``0 < k + l``, ``k, l <= order`` that is not zero everywhere (``k <= p``, ``l <= q``).
    ``ctrl`` is ``(n, m, d)``; a rational net's is the homogeneous ``(w (P - c), w)``,
    given with ``cartesian = (P, w, c)`` so that its first differences are formed from
    the Cartesian poles (:func:`homogeneous_differences`)."""
    ku, kv = np.asarray(knots_u, float), np.asarray(knots_v, float)

    def first(axis):
        return None if cartesian is None else homogeneous_differences(*cartesian, axis)

    along_u = [(ku, p, np.asarray(ctrl, float))]
    for k in range(min(order, p)):
        along_u.append(differenced(*along_u[-1], axis=0, differences=first(0) if k == 0 else None))
    nets = {}
    for k, (k_u, deg_u, net) in enumerate(along_u):
        step = (kv, q, net)
        for l in range(min(order, q) + 1):
            if k or l:
                nets[k, l] = (k_u, deg_u, step[0], step[1], step[2])
            if l < min(order, q):
                step = differenced(*step, axis=1, differences=first(1) if k == 0 and l == 0 else None)
    return nets


def curve_from_nets(knots, degree: int, ctrl: np.ndarray, t, order: int, cartesian=None,
                    positions: np.ndarray | None = None) -> np.ndarray:
    """Derivatives ``0..order`` ``(len(t), order + 1, d)`` of the curve ``ctrl``
    (``(n, d)``; rational: homogeneous, with ``cartesian`` as in :func:`derivative_nets`)
    on ``degree`` and ``knots``, each from its derivative net; the positions (order 0)
    are those of the net ``positions`` when given (the curve about its centre, whose
    differences would carry the centring's rounding), else of ``ctrl``."""
    t = np.asarray(t, dtype=float).ravel()
    column = None if cartesian is None else (cartesian[0][:, None], cartesian[1][:, None], cartesian[2])
    nets = derivative_nets(knots, degree, [0.0, 1.0], 0, ctrl[:, None], order, column)
    out = np.zeros((t.size, order + 1, ctrl.shape[-1]))
    out[:, 0] = tensor.curve_derivatives(knots, degree, ctrl if positions is None else positions, t, 0)[:, 0]
    for (k, _), (k_u, deg, _, _, poles) in nets.items():
        out[:, k] = tensor.curve_derivatives(k_u, deg, poles[:, 0], t, 0)[:, 0]
    return out
