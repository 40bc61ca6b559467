"""Hypothesis strategies and parameter helpers shared by the tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

import surfmod as sm


@st.composite
def clamped_knots(draw, n_ctrl: int, degree: int):
    """Random clamped non-uniform knots with interior multiplicities up to the degree."""
    n_inner = n_ctrl - degree - 1
    values = []
    while len(values) < n_inner:
        x = draw(st.floats(0.01, 0.99, allow_nan=False))
        mult = draw(st.integers(1, min(degree, n_inner - len(values))))
        values.extend([round(x, 3)] * mult)
    inner = sorted(values)
    # a value repeated by two draws could exceed the degree: nudge duplicates apart
    uniq, counts = np.unique(inner, return_counts=True)
    if counts.size and counts.max() > degree:
        inner = sorted(np.linspace(0.05, 0.95, n_inner))
    lo = draw(st.sampled_from([0.0, -1.0, 2.5]))
    scale = draw(st.sampled_from([1.0, 3.0, 0.25]))
    knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    return lo + scale * knots


@st.composite
def bspline_surfaces(draw, rational=None, max_degree: int = 7):
    """Random B-spline / NURBS surfaces: degrees 1..7, clamped non-uniform knots with
    repeated interior knots, weights over two orders of magnitude."""
    p = draw(st.integers(1, max_degree))
    q = draw(st.integers(1, max_degree))
    n = draw(st.integers(p + 1, p + 5))
    m = draw(st.integers(q + 1, q + 5))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    net = rng.uniform(-5, 5, (n, m, 3))
    ku = draw(clamped_knots(n, p))
    kv = draw(clamped_knots(m, q))
    is_rational = draw(st.booleans()) if rational is None else rational
    w = 10.0 ** rng.uniform(-1, 1, (n, m)) if is_rational else None
    return sm.BSplineSurface(net, (p, q), (ku, kv), w)


def _with_knots(lo, hi, knots, count):
    # a sample a few ulps off a knot (0.6 beside 0.6000000000000001) is a knot to OCCT but not
    # to an exact comparison: such samples are replaced by the knot itself
    base = np.linspace(lo, hi, count)
    inside = knots[(knots >= lo) & (knots <= hi)]
    near = np.abs(base[:, None] - inside[None, :]).min(axis=1) <= 1e-9 * (hi - lo) if inside.size else False
    return np.unique(np.concatenate([base[~near] if inside.size else base, inside]))


def parameters_with_knots(s, count: int = 7):
    """Parameters including every knot inside the domain and both ends."""
    (u0, u1), (v0, v1) = s.domain
    return _with_knots(u0, u1, s.knots[0], count), _with_knots(v0, v1, s.knots[1], count)
