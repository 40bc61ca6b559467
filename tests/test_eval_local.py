"""Local-support evaluation (surfmod/eval/local.py + kernels.py) against the textbook
formulas of tests/reference.py and against OCCT, at 1e-13 relative.

Nets from 4x4 to 400x400, degrees 1-7, repeated interior knots, parameters on every knot
and at both domain ends; polynomial and rational; grids and scattered points.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

import reference as ref
from dense_eval import surface_grid
import surfmod as sm
from strategies import bspline_surfaces, parameters_with_knots
from surfmod.eval import kernels, local
from surfmod.eval.scattered_compiled import scattered_compiled, scattered_positions_compiled
from surfmod.eval.basis import find_spans, span_buckets
from surfmod.eval.rational import surface_quotient
from surfmod.nets.knots import smooth_mask
from surfmod.occ.sample import surface_d2

REL = 1e-13


@pytest.fixture(autouse=True, scope="module", params=["default", "compiled"])
def evaluation_path(request):
    """Every test twice: with the default choice (NumPy, eval/scattered.py, for the small
    work of most tests) and with every call forced through the compiled kernels."""
    saved = local.COMPILED_SCATTERED, local.COMPILED_GRID
    if request.param == "compiled":
        local.COMPILED_SCATTERED = local.COMPILED_GRID = 0
    yield request.param
    local.COMPILED_SCATTERED, local.COMPILED_GRID = saved


@pytest.fixture
def compiled(monkeypatch):
    """Every call through the compiled kernels (tests of a compiled path: the patches)."""
    monkeypatch.setattr(local, "COMPILED_SCATTERED", 0)
    monkeypatch.setattr(local, "COMPILED_GRID", 0)
#: against OCCT's derivatives: its quotient rule rounds differently and, at rational
#: domain ends, loses about a digit where ours still meets the textbook to REL
REL_OCCT_DERIVATIVES = 1e-12


def _conditioning(s):
    """The rational quotient amplifies the rounding of the homogeneous sums by about the
    weight ratio; both sides round them differently."""
    return 1.0 if s.weights is None else float(np.sqrt(s.weights.max() / s.weights.min()))


def _assert_partials(mine, expected, s, rel=REL, mask=None, rel_ders=None):
    """Each partial (k, l) agrees to ``rel`` (``rel_ders`` for k + l > 0) times its
    largest magnitude over the sample (at least the net size for positions); past the
    degree of a polynomial net, exactly zero."""
    cond = _conditioning(s)
    for k in range(expected.shape[-3]):
        for l in range(expected.shape[-2]):
            e, m = expected[..., k, l, :], mine[..., k, l, :]
            if mask is not None:
                ok = mask(k, l)
                e, m = e[ok], m[ok]
            if e.size == 0:
                continue
            if s.weights is None and (k > s.degree[0] or l > s.degree[1]):
                # past the degree a polynomial's partial is zero, exactly so here (the
                # reference's differences of basis functions leave round-off instead)
                np.testing.assert_array_equal(m, 0.0, err_msg=f"partial ({k}, {l})")
                continue
            scale = np.abs(e).max()
            if k == l == 0:
                scale = max(scale, np.abs(s.control_points).max())
            tol = rel if k == l == 0 or rel_ders is None else rel_ders
            np.testing.assert_allclose(m, e, rtol=0, atol=tol * cond * max(scale, 1e-300),
                                       err_msg=f"partial ({k}, {l})")


def _net(n, m, rng):
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 8, m), indexing="ij")
    return np.stack([x, y, rng.uniform(-1, 1, (n, m))], axis=-1)


def _knots(n, p, rng, repeat=True, ratio=None):
    """Clamped non-uniform knots; with ``repeat`` a few interior knots of multiplicity p;
    with ``ratio`` non-empty spans within that factor of each other (the patch path takes
    only such nets: ``patches.MAX_SPAN_RATIO``)."""
    if ratio is None:
        inner = np.sort(rng.uniform(0.02, 0.98, n - p - 1))
    else:
        spans = rng.uniform(1, ratio, n - p)
        inner = np.cumsum(spans)[:-1] / spans.sum()
    if repeat and n - p - 1 >= 2 * p and p > 1:
        for start in rng.choice(np.arange(0, n - p - 1 - p, p), size=min(3, (n - p - 1) // (2 * p)), replace=False):
            inner[start : start + p] = inner[start]
        inner = np.sort(inner)
    return np.concatenate([np.zeros(p + 1), inner, np.ones(p + 1)])


def _surface(n, m, p, q, rational, seed=0, repeat=True, ratio=None):
    rng = np.random.default_rng(seed)
    w = 10.0 ** rng.uniform(-1, 1, (n, m)) if rational else None
    knots = _knots(n, p, rng, repeat, ratio), _knots(m, q, rng, repeat, ratio)
    return sm.BSplineSurface(_net(n, m, rng), (p, q), knots, w)


def _sample_params(s, count, rng):
    """Random parameters plus some knots and both domain ends, as pairs."""
    (u0, u1), (v0, v1) = s.domain
    ku = s.knots[0][(s.knots[0] >= u0) & (s.knots[0] <= u1)]
    kv = s.knots[1][(s.knots[1] >= v0) & (s.knots[1] <= v1)]
    u = np.concatenate([rng.uniform(u0, u1, count), rng.choice(ku, count), [u0, u1, u0, u1]])
    v = np.concatenate([rng.uniform(v0, v1, count), rng.choice(kv, count), [v0, v1, v1, v0]])
    return u, v


# -- against the textbook ------------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(s=bspline_surfaces())
def test_scattered_partials_match_textbook(s):
    us, vs = parameters_with_knots(s, 3)
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    (p, q), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.bspline_surface_derivatives(s.control_points, p, q, ku, kv, u, v, 2, s.weights)
                         for u, v in zip(uu, vv)])
    _assert_partials(s.derivatives(uu, vv, 2), expected, s)
    _assert_partials(s.grid_derivatives(us, vs, 2).reshape(expected.shape), expected, s)
    np.testing.assert_allclose(s.points(uu, vv), expected[:, 0, 0], rtol=0,
                               atol=REL * _conditioning(s) * np.abs(s.control_points).max())


@pytest.mark.parametrize("size", [4, 20, 100, 400])
@pytest.mark.parametrize("rational", [False, True])
def test_large_nets_match_textbook(size, rational):
    """The reference is slow (recursive Cox-de Boor over the whole net): a few points."""
    s = _surface(size, size, 3, 2, rational, seed=size)
    rng = np.random.default_rng(1)
    u, v = _sample_params(s, 3, rng)
    (p, q), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.bspline_surface_derivatives(s.control_points, p, q, ku, kv, a, b, 2, s.weights)
                         for a, b in zip(u, v)])
    _assert_partials(s.derivatives(u, v, 2), expected, s)


@pytest.mark.parametrize("degree", [1, 2, 5, 12, 25])
def test_bezier_patch_matches_bernstein_sum(degree):
    rng = np.random.default_rng(degree)
    net = rng.uniform(-1, 1, (degree + 1, 4, 3))
    w = 10.0 ** rng.uniform(-0.5, 0.5, (degree + 1, 4))
    s = sm.BezierSurface(net, w)
    t = np.linspace(0, 1, 7)
    expected = np.array([[ref.bezier_point(net, a, b, w) for b in t] for a in t])
    np.testing.assert_allclose(s.grid(t, t), expected, rtol=0, atol=REL * _conditioning(s) * 4)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    np.testing.assert_allclose(s.points(uu, vv), expected, rtol=0, atol=REL * _conditioning(s) * 4)


@pytest.mark.parametrize("rational", [False, True])
def test_curvatures_match_fundamental_forms(rational):
    s = _surface(9, 8, 3, 3, rational, seed=5)
    rng = np.random.default_rng(2)
    (u0, u1), (v0, v1) = s.domain
    u, v = rng.uniform(u0, u1, 12), rng.uniform(v0, v1, 12)
    (p, q), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.curvatures_from_partials(
        ref.bspline_surface_derivatives(s.control_points, p, q, ku, kv, a, b, 2, s.weights)) for a, b in zip(u, v)])
    c = s.curvatures(u, v)
    np.testing.assert_allclose(c.gaussian, expected[:, 0], rtol=1e-11, atol=1e-12 * np.abs(expected[:, 0]).max())
    np.testing.assert_allclose(c.mean, expected[:, 1], rtol=1e-11, atol=1e-12 * np.abs(expected[:, 1]).max())


# -- against OCCT ----------------------------------------------------------------------
def _occt_mask(s, u, v):
    (p, q), (ku, kv) = s.degree, s.knots
    # OCCT's D2 gives the partials with k + l <= 2, where the surface is that smooth
    return lambda k, l: smooth_mask(ku, p, u, k) & smooth_mask(kv, q, v, l) & (k + l <= 2)


@pytest.mark.parametrize("size", [4, 20, 100, 400])
@pytest.mark.parametrize("rational", [False, True])
def test_scattered_and_grid_match_occt_for_every_net_size(size, rational):
    s = _surface(size, size + 1, 3, 3, rational, seed=size)
    rng = np.random.default_rng(size)
    u, v = _sample_params(s, 200, rng)
    occ = surface_d2(s.geom(), u, v)
    mine = s.derivatives(u, v, 2)
    _assert_partials(mine, occ, s, mask=_occt_mask(s, u, v), rel_ders=REL_OCCT_DERIVATIVES)
    us, vs = np.sort(u[:40]), np.sort(v[:30])
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    grid = s.grid_derivatives(us, vs, 2).reshape(-1, 3, 3, 3)
    _assert_partials(grid, surface_d2(s.geom(), uu, vv), s, mask=_occt_mask(s, uu, vv), rel_ders=REL_OCCT_DERIVATIVES)
    np.testing.assert_array_equal(s.grid(us, vs), s.grid_derivatives(us, vs, 0)[:, :, 0, 0])


@pytest.mark.parametrize("p", range(1, 8))
@pytest.mark.parametrize("rational", [False, True])
def test_every_degree_matches_occt(p, rational):
    q = 8 - p
    s = _surface(p + 12, q + 9, p, q, rational, seed=p)
    rng = np.random.default_rng(p)
    u, v = _sample_params(s, 60, rng)
    _assert_partials(s.derivatives(u, v, 2), surface_d2(s.geom(), u, v), s, mask=_occt_mask(s, u, v), rel_ders=REL_OCCT_DERIVATIVES)
    np.testing.assert_allclose(s.points(u, v), surface_d2(s.geom(), u, v)[:, 0, 0], rtol=0,
                               atol=REL * _conditioning(s) * 10)


# -- the machinery -------------------------------------------------------------------------
def test_grid_blocks_and_preallocated_output_agree():
    """A grid whose v-points go in several chunks of the ring; ``grid_into`` writes the
    same numbers into the caller's buffer."""
    s = _surface(300, 40, 3, 3, True, seed=9, repeat=False)
    us, vs = np.linspace(0, 1, 701), np.linspace(0, 1, 3000)
    old = local.CHUNK
    try:
        local.CHUNK = 128  # force many chunks
        blocked = s.grid(us, vs)
    finally:
        local.CHUNK = old
    np.testing.assert_array_equal(blocked, s.grid(us, vs))
    buf = np.empty((us.size, vs.size, 3))
    assert s.grid_into(us, vs, buf) is buf
    np.testing.assert_array_equal(buf, blocked)
    uu, vv = np.meshgrid(us[::50], vs[::300], indexing="ij")
    np.testing.assert_allclose(blocked[::50, ::300], s.points(uu, vv), rtol=0, atol=1e-14 * 10)


def test_grid_into_names_a_bad_buffer():
    s = _surface(6, 6, 3, 3, False)
    with pytest.raises(sm.SurfmodError, match="out"):
        s.grid_into([0, 1], [0, 1], np.empty((2, 3, 3)))


def test_span_search_matches_numpy():
    knots = np.array([0, 0, 0, 0.2, 0.2, 0.5, 0.7, 1, 1, 1.0])
    t = np.concatenate([np.linspace(0, 1, 41), knots])
    expected = find_spans(knots, 2, 7, t)
    bucket = span_buckets(knots, 2, 7)
    got = np.array([kernels.find_span_bucketed(knots, 2, 7, x, *bucket) for x in t])
    np.testing.assert_array_equal(got, expected)


def test_empty_inputs():
    s = _surface(6, 6, 3, 3, True)
    assert s.points(np.empty(0), np.empty(0)).shape == (0, 3)
    assert s.grid_derivatives(np.empty(0), [0.5], 2).shape == (0, 1, 3, 3, 3)


@settings(max_examples=25, deadline=None)
@given(s=bspline_surfaces())
def test_local_kernels_equal_the_dense_blas_path(s):
    """An independent algorithm: dense basis matrices and two GEMMs (tests/dense_eval.py)
    with the NumPy quotient rule (eval/rational.py)."""

    us, vs = parameters_with_knots(s, 6)
    (p, q), (ku, kv) = s.degree, s.knots
    dense = surface_grid(ku, p, kv, q, s._homogeneous, us, vs, 2, planar=s.rational)
    if s.rational:
        dense = surface_quotient(dense)
    _assert_partials(s.grid_derivatives(us, vs, 2), dense, s)


# -- per-span patches (eval/patches.py) and preallocated partials ----------------------------
@pytest.mark.parametrize("p, q", [(1, 1), (2, 3), (3, 1), (3, 3)])
@pytest.mark.parametrize("rational", [False, True])
def test_patch_positions_match_basis_kernel_and_textbook(p, q, rational, compiled):
    """Many scattered points on a small net go through the per-span Taylor patches; they
    agree with the basis-function kernel everywhere and with the textbook sums on a
    sample, including knots (repeated ones too) and both domain ends."""
    s = _surface(11, 9, p, q, rational, seed=p * 10 + q, ratio=3.0)
    rng = np.random.default_rng(4)
    u, v = _sample_params(s, 3000, rng)
    net = s._local_net()
    net.cache.clear()
    assert 2 * 3000 + 4 >= local.PATCH_MIN_POINTS
    got = s.points(u, v)
    assert "patches" in net.cache  # the patch path ran
    basis = np.empty_like(got)
    scattered_positions_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, u, v, net.rational,
                                 net.inv_u, net.inv_v, net.bucket_u, net.bucket_v, basis)
    atol = REL * _conditioning(s) * np.abs(s.control_points).max()
    np.testing.assert_allclose(got, basis, rtol=0, atol=atol)
    pick = np.r_[0:40, 3000:3040, -4:0]
    (pp, qq), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.bspline_surface_derivatives(s.control_points, pp, qq, ku, kv, u[i], v[i], 0, s.weights)[0, 0]
                         for i in pick])
    np.testing.assert_allclose(got[pick], expected, rtol=0, atol=atol)


@pytest.mark.parametrize("p, q", [(1, 1), (2, 3), (3, 1), (3, 3)])
@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("order", [1, 2])
def test_patch_partials_match_basis_kernel_and_textbook(p, q, rational, order, compiled):
    """Partials to order 1 and 2 of many scattered points go through the patches too
    (Horner schemes with their derivatives, the chain rule, the quotient rule): they
    agree with the basis-function kernel everywhere and with the textbook on a sample,
    knots and domain ends included."""
    s = _surface(11, 9, p, q, rational, seed=p * 10 + q, ratio=3.0)
    u, v = _sample_params(s, 3000, np.random.default_rng(6))
    net = s._local_net()
    net.cache.clear()
    got = s.derivatives(u, v, order)
    assert "patches" in net.cache  # the patch path ran
    basis = np.empty_like(got)
    scattered_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, u, v, order, net.rational,
                       kernels.binomials(order), net.inv_u, net.inv_v, net.bucket_u, net.bucket_v, basis)
    _assert_partials(got, basis, s)
    pick = np.r_[0:40, 3000:3040, -4:0]
    (pp, qq), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.bspline_surface_derivatives(s.control_points, pp, qq, ku, kv, u[i], v[i], order, s.weights)
                         for i in pick])
    # past the degree the textbook's differences of basis functions leave rounding noise
    # where the patches' Horner schemes give exact zeros (polynomial nets)
    _assert_partials(got[pick], expected, s, mask=lambda k, l: k <= pp and l <= qq)
    if not rational:
        assert not got[:, pp + 1 :].any() and not got[:, :, qq + 1 :].any()


def test_patches_are_skipped_for_high_degree_and_few_points():
    s = _surface(9, 9, 4, 3, True)
    u, v = _sample_params(s, 3000, np.random.default_rng(1))
    s.points(u, v)
    assert "patches" not in s._local_net().cache  # degree 4: the basis kernel
    s3 = _surface(9, 9, 3, 3, True)
    s3.points(u[:100], v[:100])
    assert "patches" not in s3._local_net().cache  # 100 points: not worth a table


@pytest.mark.parametrize("rational", [False, True])
def test_grid_into_partials_equal_grid_derivatives_and_textbook(rational):
    s = _surface(30, 12, 3, 2, rational, seed=5)
    us, vs = parameters_with_knots(s, 7)
    buf = np.full((us.size, vs.size, 3, 3, 3), np.nan)
    assert s.grid_into(us, vs, buf, order=2) is buf
    planar = s.grid_derivatives(us, vs, 2)
    np.testing.assert_array_equal(buf, planar)  # the same kernel, into the caller's array
    (p, q), (ku, kv) = s.degree, s.knots
    expected = np.array([[ref.bspline_surface_derivatives(s.control_points, p, q, ku, kv, u, v, 2, s.weights)
                          for v in vs] for u in us])
    _assert_partials(buf, expected, s)


def test_grid_into_partials_names_a_bad_buffer_or_order():
    s = _surface(6, 6, 3, 3, True)
    with pytest.raises(sm.SurfmodError, match="out"):
        s.grid_into([0, 1], [0, 1], np.empty((2, 2, 3)), order=1)
    with pytest.raises(sm.SurfmodError, match="order"):
        s.grid_into([0, 1], [0, 1], np.empty((2, 2, 3)), order=-1)


def test_partials_skip_the_output_check_only_when_provably_finite():
    """Bounded partials of a finite net with positive weights are finite; nets that could
    overflow or whose weights could underflow keep the check (a NaN pole is reported)."""
    s = _surface(6, 6, 3, 3, True)
    for order in range(4):
        assert local.partials_finite(s._local_net(), order)
    net = s.control_points.copy()
    scale = 1e289 / (16 * np.abs(net).max())  # positions bound: 16 poles x max |P|
    assert local.partials_finite(sm.BSplineSurface._trusted(net * scale, s.degree, s.knots)._local_net(), 0)
    huge = sm.BSplineSurface._trusted(net * scale * 100, s.degree, s.knots)
    assert not local.partials_finite(huge._local_net(), 0)
    assert np.isfinite(huge.grid_derivatives([0.5], [0.5], 2)).all()  # checked, and finite
    tiny_w = sm.BSplineSurface._trusted(net, s.degree, s.knots, np.full(net.shape[:2], 1e-300))
    assert not local.partials_finite(tiny_w._local_net(), 0)
    net[2, 3, 1] = np.nan
    bad = sm.BSplineSurface._trusted(net, s.degree, s.knots)
    assert not local.partials_finite(bad._local_net(), 0)
    with pytest.raises(sm.SurfmodError, match="u, v"):
        bad.points([0.5], [0.5])
    with pytest.raises(sm.SurfmodError, match="u, v"):
        bad.derivatives([0.5], [0.5], 1)
    with pytest.raises(sm.SurfmodError, match="not finite"):
        bad.grid([0.5], [0.5])


@pytest.mark.parametrize("rational", [False, True])
def test_partial_bounds_hold(rational):
    """The bounds that let evaluation skip the output check are upper bounds: sampled
    partials (on knots and ends too) of nets with short spans, repeated knots and a weight
    ratio up to 100 stay below them."""
    for seed in range(4):
        s = _surface(12, 9, 3, 2, rational, seed=seed)
        u, v = _sample_params(s, 300, np.random.default_rng(seed))
        ders = np.abs(s.derivatives(u, v, 3)).max(axis=(0, 3))
        bound = local.partial_bounds(s._local_net(), 3)
        assert np.all(ders <= bound), (ders / bound).max()
