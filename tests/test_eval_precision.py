"""surfmod's evaluator against the 40-digit reference (:mod:`surfmod.nets.mp_reference`)
on a stress family built here, and against OCCT's own error on it (issue 35).

Every path is held to the same bar: the NumPy twins (``eval/scattered.py``, ``eval/tensor_grid.py``), the compiled
scattered kernel, the per-span patches, the compiled and the NumPy grids.  Positions,
partials to order 2, normals and curvatures stay within ``max(OCCT's error, 1e-12)``
relative of the reference, the bar of issue 35 (each order relative to its largest
reference magnitude over the case, curvatures to the larger principal curvature at the
point); surfmod in fact keeps 1e-12 on every case, also where OCCT does not (the
high-degree Béziers, the far NURBS curve), and that is what is asserted.  Nothing is cached:
the reference costs a few milliseconds a point, so a case takes a dozen points.
"""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.eval import derivative_nets, local
from surfmod.eval.differential import curvatures, unit_normals
from surfmod.nets import mp_reference
from surfmod.occ.sample import curve_d2, surface_props, surface_values_d2

#: the bar of issue 35, where OCCT does better than it
REL = 1e-12
ORDERS = {0: [(0, 0)], 1: [(1, 0), (0, 1)], 2: [(2, 0), (1, 1), (0, 2)]}


def _clamped(inner, p, a, b):
    return np.r_[[float(a)] * (p + 1), np.asarray(inner, float), [float(b)] * (p + 1)]


def _wavy(rng, n, m, size=(100.0, 60.0), amp=8.0, origin=(0.0, 0.0, 0.0)):
    x, y = np.meshgrid(np.linspace(0, size[0], n), np.linspace(0, size[1], m), indexing="ij")
    z = amp * np.sin(x / size[0] * 5.1) * np.cos(y / size[1] * 3.3) + rng.normal(0, amp / 10, (n, m))
    return np.stack([x, y, z], -1) + np.asarray(origin, float)


def _crowded(rng, count, p, a, b, short):
    """Clamped knots on ``[a, b]`` whose interior spans are, one in three, ``short`` of the
    others' length (as the real faces of issue 35: spans of 1e-5 beside 1000x longer)."""
    widths = np.where(np.arange(count + 1) % 3 == 1, short, 1.0) * rng.uniform(0.5, 1.5, count + 1)
    return _clamped(a + (b - a) * np.cumsum(widths)[:-1] / widths.sum(), p, a, b)


def _graded_sliver(rational=False):
    """A bicubic face like ansys_race_car_nose.stp's face 121 (issue 38): u-knots 3e-3 from
    zero whose spans halve down to 8.8e-10 and grow again, poles 900 mm from the origin
    and 1e-6 mm apart where the spans are short."""
    rng = np.random.default_rng(5)
    u0 = 0.00313738246065294
    spans = np.r_[3.5e-9, 1.77e-9, 8.8e-10, 8.8e-10, 7.1e-9, 1.41e-8, 2.83e-8, 5.65e-8, 1.13e-7, 2.26e-7, 4.5e-7,
                  9e-7, 1.8e-6, 3.6e-6, 7.2e-6, 1.4e-5]
    ku = _clamped(u0 + np.cumsum(spans)[:-1], 3, u0, u0 + spans.sum())
    kv = _clamped(np.linspace(0, 1, 9)[1:-1], 3, 0, 1)
    gu = np.array([ku[i + 1:i + 4].mean() for i in range(len(ku) - 4)])[:, None]
    gv = np.array([kv[j + 1:j + 4].mean() for j in range(len(kv) - 4)])[None, :]
    x = 900 + 1000 * (gu - u0) + 0 * gv
    y = -40 + 30 * gv + 20 * ((gu - u0) / spans.sum()) ** 2
    z = 250 + 5 * np.sin(3 * gv) + 1000 * (gu - u0) ** 2 / spans.sum() + rng.normal(0, 1e-9, (len(gu), 1))
    w = np.broadcast_to(1.0 + 0.5 * np.sin(5 * gv), x.shape) if rational else None
    return sm.BSplineSurface(np.stack(np.broadcast_arrays(x, y, z), -1), (3, 3), (ku, kv), weights=w)


def _surfaces():
    rng = np.random.default_rng(35)
    w = np.exp(rng.uniform(0, np.log(1e4), (7, 6)))
    th = np.linspace(0, 2 * np.pi, 9)[:-1]
    ring = np.stack([30 * np.cos(th), 20 * np.sin(th)], -1)
    tube = np.stack([np.c_[ring * (1 + 0.1 * k), np.full(8, 10.0 * k)] for k in range(5)], 1)
    collapsed = _wavy(rng, 6, 6)
    collapsed[0] = collapsed[0].mean(axis=0)
    return {
        # the three kinds of real faces where surfmod's curvature was 1e-7..4e-6 off
        "crowded u, domain below zero": sm.BSplineSurface(
            _wavy(rng, 21, 4), (3, 3), (_crowded(rng, 17, 3, -3.7, 12.3, 1e-5), _clamped([], 3, 0, 1))),
        "degree 5, triple knots, 0..189": sm.BSplineSurface(
            _wavy(rng, 21, 6), (5, 5), (_clamped(np.repeat(np.linspace(0, 189, 7)[1:-1], 3), 5, 0, 189),
                                        _clamped([], 5, 0, 189))),
        "4 x 48, double knots in v": sm.BSplineSurface(
            _wavy(rng, 4, 48, (30, 300)), (3, 3),
            (_clamped([], 3, 0, 1), _clamped(np.repeat(np.linspace(0, 1, 24)[1:-1], 2), 3, 0, 1))),
        "spans 1e-6, range 1e4 wide": sm.BSplineSurface(
            _wavy(rng, 12, 7), (3, 2), (_crowded(rng, 8, 3, -2e3, 8e3, 1e-6),
                                        _clamped(np.linspace(0, 1, 6)[1:-1], 2, 0, 1))),
        "range 1e-3 wide at 7, spans 1e-3": sm.BSplineSurface(
            _wavy(rng, 9, 8), (4, 3), (_crowded(rng, 4, 4, 7.0, 7.001, 1e-3),
                                       _clamped([7.0003, 7.0003, 7.0006, 7.0008], 3, 7.0, 7.001))),
        "degree 1 x 2": sm.BSplineSurface(
            _wavy(rng, 5, 6), (1, 2), (_clamped([0.2, 0.5, 0.6], 1, 0, 1), _clamped([0.3, 0.3, 0.7], 2, 0, 1))),
        "degree 9 x 7, interior multiplicity p": sm.BSplineSurface(
            _wavy(rng, 19, 16), (9, 7), (_clamped([0.4] * 9, 9, 0, 1), _clamped([0.3] * 7 + [0.5], 7, 0, 1))),
        "Bezier 12 x 25": sm.BezierSurface(_wavy(rng, 13, 26)),
        "NURBS, weights 1 to 1e4": sm.BSplineSurface(
            _wavy(rng, 7, 6), (3, 2), (_clamped([0.25, 0.5, 0.75], 3, 0, 1), _clamped([0.3, 0.6, 0.61], 2, 0, 1)),
            weights=w),
        "NURBS, weights 1 to 1e3 (per-span patches)": sm.BSplineSurface(
            _wavy(rng, 7, 6), (3, 2), (_clamped([0.25, 0.5, 0.75], 3, 0, 1), _clamped([0.3, 0.6, 0.61], 2, 0, 1)),
            weights=np.exp(rng.uniform(0, np.log(1e3), (7, 6)))),
        "1e6 from the origin": sm.BSplineSurface(
            _wavy(rng, 8, 8, origin=(1e6, -1e6, 5e5)), (3, 3),
            (_clamped([0.2, 0.4, 0.6, 0.8], 3, 0, 1), _clamped([0.2, 0.4, 0.6, 0.8], 3, 0, 1))),
        "NURBS 1e5 from the origin": sm.BSplineSurface(
            _wavy(rng, 7, 6, origin=(-3e4, 1e5, 2e4)), (3, 2),
            (_clamped([0.25, 0.5, 0.75], 3, 0, 1), _clamped([0.3, 0.6, 0.61], 2, 0, 1)), weights=w[::-1]),
        "periodic in u": sm.BSplineSurface(  # unclamped uniform knots, the first p poles repeated
            np.concatenate([tube, tube[:3]]), (3, 3), (np.arange(-3.0, 12.0) * 0.7 + 5.0, _clamped([0.5], 3, 0, 1))),
        "graded sliver 900 mm out (issue 38)": _graded_sliver(),
        "graded NURBS sliver, weights along v": _graded_sliver(rational=True),
        "collapsed pole row": sm.BSplineSurface(
            collapsed, (3, 3), (_clamped([0.5, 0.5], 3, 0, 1), _clamped([0.4, 0.7], 3, 0, 1))),
    }


SURFACES = _surfaces()


def _parameters(domain, knots, rng, count=12):
    """``count`` random parameters, half of them inside the shortest spans if there are any."""
    a, b = domain
    t = rng.uniform(a, b, count)
    gaps = np.diff(np.asarray(knots, float))
    short = np.where((gaps > 0) & (gaps < 2e-3 * (b - a)))[0][: count // 2]
    t[: short.size] = knots[short] + gaps[short] * rng.uniform(0.05, 0.95, short.size)
    return t


def _reference(points, weights, degree, knots, u, v):
    out = np.full((u.size, 3, 3, 3), np.nan)
    for a in range(u.size):
        for (k, l), x in mp_reference.mp_partials(points, weights, degree, knots, u[a], v[a]).items():
            out[a, k, l] = [float(c) for c in x]
    return out


def _errors(mine, ref):
    """Per order the largest deviation over the points, relative to the largest reference
    partial of that order."""
    return [max(np.abs(mine[:, k, l] - ref[:, k, l]).max() for k, l in ij)
            / max(max(np.abs(ref[:, k, l]).max() for k, l in ij), 1e-300) for ij in ORDERS.values()]


def _curvature_error(k, k_ref):
    scale = np.abs(k_ref[:, 2:]).max(axis=1)
    return float(np.max(np.maximum(np.abs(k[:, 0] - k_ref[:, 0]) / scale**2,
                                   np.abs(k[:, 1:] - k_ref[:, 1:]).max(axis=1) / scale)))


def _paths(s, u, v):
    """Partials to order 2 at the pairs ``(u, v)`` from every evaluation path."""
    (p, q), (ku, kv) = s.degree, s.knots

    def net():
        return local.prepare(ku, p, kv, q, s._homogeneous, s.control_points, s.weights)

    def diagonal(grid):
        return grid[np.argsort(np.argsort(u)), np.arange(v.size)]

    out = {"numpy": local.surface_derivatives(net(), u, v, 2),
           "numpy grid": diagonal(local.surface_grid(net(), np.sort(u), v, 2))}
    saved = local.COMPILED_SCATTERED, local.COMPILED_GRID, local.PATCH_MIN_POINTS, local.PATCH_POINTS_PER_SPAN
    try:
        local.COMPILED_SCATTERED = local.COMPILED_GRID = 0
        out["compiled"] = local.surface_derivatives(net(), u, v, 2)
        out["compiled grid"] = diagonal(local.surface_grid(net(), np.sort(u), v, 2))
        positions = local.surface_points(net(), u, v)
        grid_positions = diagonal(local.surface_grid(net(), np.sort(u), v, 0))
        if max(p, q) <= 3:
            local.PATCH_MIN_POINTS = local.PATCH_POINTS_PER_SPAN = 0
            out["patches"] = local.surface_derivatives(net(), u, v, 2)
            positions = np.stack([positions, local.surface_points(net(), u, v)])
    finally:
        local.COMPILED_SCATTERED, local.COMPILED_GRID, local.PATCH_MIN_POINTS, local.PATCH_POINTS_PER_SPAN = saved
    return out, np.concatenate([positions.reshape(-1, u.size, 3), grid_positions[None, :, 0, 0]])


@pytest.mark.parametrize("name", SURFACES)
def test_surface_within_occt_and_reference(name):
    s = SURFACES[name]
    rng = np.random.default_rng(len(name))
    u = _parameters(s.domain[0], s.knots[0], rng)
    v = _parameters(s.domain[1], s.knots[1], rng)
    ref = _reference(s.control_points, s.weights, s.degree, s.knots, u, v)
    geom = s.geom()
    occ = _errors(surface_values_d2(geom, u, v), ref)
    paths, positions = _paths(s, u, v)
    for path, ders in paths.items():
        errs = _errors(ders, ref)
        assert np.all(np.array(errs) <= REL), f"{path}: errors {errs} per order (OCCT's {occ})"
    pos_scale = np.abs(ref[:, 0, 0]).max()
    assert np.abs(positions - ref[None, :, 0, 0]).max() <= 1e-14 * pos_scale  # a few ulps
    if name == "collapsed pole row":
        return  # normals and curvatures are judged where they are defined: the cases below
    normals, k_occ = surface_props(geom, u, v)
    k_ref = np.array([mp_reference.mp_curvatures(s.control_points, s.weights, s.degree, s.knots, a, b)
                      for a, b in zip(u, v)])
    n_ref = unit_normals(ref)
    k_occ, n_occ = _curvature_error(k_occ, k_ref), np.abs(normals - n_ref).max()
    for path, ders in paths.items():
        assert np.abs(unit_normals(ders) - n_ref).max() <= REL, (path, n_occ)
        assert _curvature_error(np.stack(curvatures(ders), axis=1), k_ref) <= REL, (path, k_occ)


def test_crowded_knots_take_the_derivative_nets(monkeypatch):
    """The graded sliver's partials are right because its partials come from the
    derivative nets: the usual sum of basis derivatives times poles loses 1e-8 of the
    second partials there (the basis derivatives themselves are right to 1e-16)."""
    s = _graded_sliver()
    rng = np.random.default_rng(7)
    u = _parameters(s.domain[0], s.knots[0], rng)
    v = _parameters(s.domain[1], s.knots[1], rng)
    ref = _reference(s.control_points, s.weights, s.degree, s.knots, u, v)
    (p, q), (ku, kv) = s.degree, s.knots

    def second_partials_error():
        return _errors(local.surface_derivatives(local.prepare(ku, p, kv, q, s._homogeneous, s.control_points), u, v,
                                                 2), ref)[2]

    assert second_partials_error() <= REL
    monkeypatch.setattr(derivative_nets, "CROWDED", np.inf)
    assert second_partials_error() > 1e-10


def test_principal_curvatures_keep_their_digits_near_an_umbilic():
    """On a near-sphere ``k1 - k2`` is small and ``H -+ sqrt(H^2 - K)`` kept half of the
    digits (2e-10 relative here, the real faces of issue 35 up to 4e-6); the shape
    operator's eigenvalues in an orthonormal frame keep them all, as OCCT's ``GeomLProp``
    (which solves for the principal directions) does."""
    th, ph = np.meshgrid(np.linspace(0.3, 1.2, 30), np.linspace(0.2, 1.3, 30), indexing="ij")
    sphere = 37.0 * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    s = sm.interpolate(sphere + np.array([1e3, -2e3, 5e2]), degree=(3, 3))
    rng = np.random.default_rng(3)
    u, v = rng.uniform(0, 1, 10), rng.uniform(0, 1, 10)
    k_ref = np.array([mp_reference.mp_curvatures(s.control_points, s.weights, s.degree, s.knots, a, b)
                      for a, b in zip(u, v)])
    assert np.all(k_ref[:, 2] - k_ref[:, 3] < 1e-2 * np.abs(k_ref[:, 2]))  # near-umbilic everywhere
    k = np.stack(s.curvatures(u, v), axis=1)
    _, k_occ = surface_props(s.geom(), u, v)
    assert _curvature_error(k, k_ref) <= max(_curvature_error(k_occ, k_ref), REL)
    assert _curvature_error(k, k_ref) < 1e-13


def _curves():
    rng = np.random.default_rng(36)
    sliver = _graded_sliver()
    pts = _wavy(rng, 26, 1)[:, 0]
    pts[:, 1] = 10 * np.cos(np.arange(26) * 0.7)
    return {
        "Bezier 25": sm.BezierCurve(pts),
        "degree 9, spans 1e-6, range 1e4 wide": sm.BSplineCurve(pts[:20], 9, _crowded(rng, 10, 9, -4e3, 6e3, 1e-6)),
        "degree 4, multiplicity 4, range 1e-3 wide": sm.BSplineCurve(
            pts[:12], 4, _clamped([2.0002, 2.0002, 2.0002, 2.0002, 2.0005, 2.0007, 2.0009], 4, 2.0, 2.001)),
        "NURBS, weights 1 to 1e4, 1e6 from the origin": sm.BSplineCurve(
            pts[:9] + 1e6, 3, _clamped([0.2, 0.3, 0.3, 0.5, 0.8], 3, 0, 1), weights=np.exp(rng.uniform(0, 9.2, 9))),
        "rational Bezier 12": sm.BezierCurve(pts[:13], weights=np.exp(rng.uniform(0, 9.2, 13))),
        "graded, 900 mm out (issue 38)": sm.BSplineCurve(sliver.control_points[:, 2], 3, sliver.knots[0]),
    }


CURVES = _curves()


@pytest.mark.parametrize("name", CURVES)
def test_curve_within_occt_and_reference(name):
    c = CURVES[name]
    t = _parameters(c.domain, c.knots, np.random.default_rng(len(name)))
    # a curve is the surface of one pole column, of degree 0 in v
    ref = _reference(c.control_points[:, None], None if c.weights is None else c.weights[:, None],
                     (c.degree, 0), (c.knots, [0.0, 1.0]), t, np.full(t.size, 0.5))[:, :, 0]
    occ = curve_d2(c.geom(), t)
    for k in range(3):
        scale = np.abs(ref[:, k]).max()
        err = np.abs(c.derivatives(t, 2)[:, k] - ref[:, k]).max() / scale
        assert err <= REL, (k, err, np.abs(occ[:, k] - ref[:, k]).max() / scale)


