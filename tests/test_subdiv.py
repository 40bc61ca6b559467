"""Catmull–Clark and Loop subdivision, limit masks, and their bad input."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.subdiv import topology as tp

CUBE_V = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)], float)
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
TET_V = np.array([(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)], float)
TET_F = [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]


def pentagonal_prism():
    """A closed cage with mixed faces: two pentagons and five quads (outward winding)."""
    a = 2 * np.pi * np.arange(5) / 5
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(5)], 1)
    v = np.concatenate([ring, ring + [0, 0, 1.5]])
    faces = [list(range(4, -1, -1)), list(range(5, 10))]
    faces += [[i, (i + 1) % 5, 5 + (i + 1) % 5, 5 + i] for i in range(5)]
    return v, faces


def torus_cage(n=6, m=5, big=3.0, small=1.0, jitter=0.0, seed=0):
    """A periodic n x m quad grid on a torus: every vertex has valence 4 (all regular)."""
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = 2 * np.pi * i / n, 2 * np.pi * j / m
    net = np.stack([(big + small * np.cos(b)) * np.cos(a), (big + small * np.cos(b)) * np.sin(a), small * np.sin(b)], -1)
    net = net + jitter * np.random.default_rng(seed).standard_normal(net.shape)
    idx = lambda ii, jj: (ii % n) * m + jj % m  # noqa: E731
    faces = np.array([[idx(p, q), idx(p + 1, q), idx(p + 1, q + 1), idx(p, q + 1)] for p in range(n) for q in range(m)])
    return net, faces


def counts(vertices, faces):
    _, topo = tp.polygon_mesh(vertices, faces)
    return topo.n_vertices, topo.n_edges, topo.n_faces, int(topo.sizes.sum())


# ---------------------------------------------------------------------------------------
# combinatorics: Euler's formulas
@pytest.mark.parametrize("cage", ["cube", "prism", "open_box"])
def test_catmull_clark_counts_follow_euler(cage):
    if cage == "cube":
        v, f = CUBE_V, CUBE_F
    elif cage == "prism":
        v, f = pentagonal_prism()
    else:
        v, f = CUBE_V, CUBE_F[:5]
    nv, ne, nf, nk = counts(v, f)
    chi = nv - ne + nf
    for level in (1, 2, 3):
        m = sm.catmull_clark(v, f, level)
        mv, me, mf, _ = counts(m.vertices, m.faces)
        assert (mv, me, mf) == (nv + ne + nf, 2 * ne + nk, nk)
        assert mv - me + mf == chi  # Euler characteristic is kept
        assert m.faces.shape[1] == 4
        nv, ne, nf, nk = mv, me, mf, 4 * mf


def test_loop_counts_follow_euler():
    v, f = TET_V, TET_F
    nv, ne, nf, _ = counts(v, f)
    for level in (1, 2, 3):
        m = sm.loop_subdivide(v, f, level)
        mv, me, mf, _ = counts(m.vertices, m.faces)
        assert (mv, me, mf) == (nv + ne, 2 * ne + 3 * nf, 4 * nf)
        assert mv - me + mf == 2
        nv, ne, nf = mv, me, mf


@pytest.mark.parametrize("scheme", ["cc", "cc_prism", "loop"])
def test_subdivided_closed_cage_is_watertight(scheme):
    if scheme == "cc":
        m = sm.catmull_clark(CUBE_V, CUBE_F, 3)
    elif scheme == "cc_prism":
        m = sm.catmull_clark(*pentagonal_prism(), 3)
    else:
        m = sm.loop_subdivide(TET_V, TET_F, 3)
    t = m.to_trimesh()
    assert t.is_watertight and t.is_winding_consistent
    assert t.volume > 0  # outward winding kept
    assert m.info["levels"] == 3


# ---------------------------------------------------------------------------------------
# regular grids reproduce uniform cubic B-spline refinement
def periodic_refinement(n):
    """(2n, n) matrix of one midpoint-knot insertion of a periodic uniform cubic B-spline."""
    s = np.zeros((2 * n, n))
    for i in range(n):
        s[2 * i, [(i - 1) % n, i, (i + 1) % n]] = [1 / 8, 6 / 8, 1 / 8]
        s[2 * i + 1, [i, (i + 1) % n]] = [1 / 2, 1 / 2]
    return s


def test_regular_grid_gives_refined_bspline_control_points():
    n, m = 6, 5
    net, faces = torus_cage(n, m, jitter=0.1)
    out = sm.catmull_clark(net.reshape(-1, 3), faces, 1)
    refined = np.einsum("ai,ijk,bj->abk", periodic_refinement(n), net, periodic_refinement(m))
    # CC numbering: vertex points, edge points (topology order), face points
    _, topo = tp.polygon_mesh(net.reshape(-1, 3), faces)
    nv, ne = n * m, topo.n_edges
    ij = lambda k: (k // m, k % m)  # noqa: E731
    got = np.empty_like(refined)
    for k in range(nv):
        i, j = ij(k)
        got[2 * i, 2 * j] = out.vertices[k]
    for e, (a, b) in enumerate(topo.edges):
        (ia, ja), (ib, jb) = ij(a), ij(b)
        i = 2 * ia + 1 if ia != ib and (ib - ia) % n == 1 else (2 * ib + 1 if ia != ib else 2 * ia)
        j = 2 * ja + 1 if ja != jb and (jb - ja) % m == 1 else (2 * jb + 1 if ja != jb else 2 * ja)
        got[i, j] = out.vertices[nv + e]
    for f in range(len(faces)):
        i, j = ij(faces[f][0])
        got[2 * i + 1, 2 * j + 1] = out.vertices[nv + ne + f]
    np.testing.assert_allclose(got, refined, atol=1e-14)

    # and the refined net describes the same uniform cubic B-spline surface
    wrap = lambda p: np.concatenate([p, p[:3]], 0)  # noqa: E731
    coarse = sm.BSplineSurface.uniform_cubic(wrap(wrap(net).transpose(1, 0, 2)).transpose(1, 0, 2))
    fine = sm.BSplineSurface.uniform_cubic(wrap(wrap(refined).transpose(1, 0, 2)).transpose(1, 0, 2))
    u = np.linspace(0, n, 13)
    v = np.linspace(0, m, 11)
    # coarse patch i covers [i, i+1]; the refined control point 2i sits under coarse point i,
    # so coarse parameter u is fine parameter 2u - 1 (shifted by the net's start offset)
    fu, fv = (2 * u + 1) % (2 * n), (2 * v + 1) % (2 * m)
    np.testing.assert_allclose(fine.grid(fu, fv), coarse.grid(u, v), atol=1e-12)


def test_open_boundary_follows_cubic_bspline_curve_rules():
    """Boundary vertex (a + 6v + b) / 8, boundary edge midpoint: the closed cubic B-spline
    refinement of the boundary polygon of an open box."""
    open_box = CUBE_F[:1] + CUBE_F[2:]  # the top face removed
    out = sm.catmull_clark(CUBE_V, open_box, 1)
    top = CUBE_V[[4, 5, 6, 7]]  # the open rim, in order
    s = periodic_refinement(4)
    refined = s @ top
    _, topo = tp.polygon_mesh(CUBE_V, open_box)
    np.testing.assert_allclose(out.vertices[[4, 5, 6, 7]], refined[::2], atol=1e-15)
    for i in range(4):
        a, b = sorted((4 + i, 4 + (i + 1) % 4))
        e = int(np.flatnonzero((topo.edges[:, 0] == a) & (topo.edges[:, 1] == b))[0])
        np.testing.assert_allclose(out.vertices[8 + e], refined[2 * i + 1], atol=1e-15)


def test_single_face_boundary_vertices_are_corners():
    """Corners of an open quad grid and the tips of a triangle strip stay put."""
    quad_v = np.array([(0, 0, 0), (1, 0, 0.3), (2, 0, 0), (0, 1, 0), (1, 1, 1), (2, 1, 0)], float)
    quad_f = [(0, 1, 4, 3), (1, 2, 5, 4)]
    m = sm.catmull_clark(quad_v, quad_f, 3)
    np.testing.assert_array_equal(m.vertices[[0, 2, 3, 5]], quad_v[[0, 2, 3, 5]])
    lim = sm.catmull_clark_limit(quad_v, quad_f)
    np.testing.assert_array_equal(lim.positions[[0, 2, 3, 5]], quad_v[[0, 2, 3, 5]])
    # the middle boundary vertex follows the curve rule (a + 6v + b) / 8
    np.testing.assert_allclose(sm.catmull_clark(quad_v, quad_f, 1).vertices[1], (quad_v[0] + 6 * quad_v[1] + quad_v[2]) / 8)
    tri_f = [(0, 1, 3), (1, 4, 3), (1, 2, 4), (2, 5, 4)]
    t = sm.loop_subdivide(quad_v, tri_f, 3)
    np.testing.assert_array_equal(t.vertices[[0, 5]], quad_v[[0, 5]])
    np.testing.assert_array_equal(sm.loop_limit(quad_v, tri_f).positions[[0, 5]], quad_v[[0, 5]])


def test_all_creases_keep_the_cube():
    """Every cube edge sharp: corners stay, edges stay straight, faces stay flat."""
    edges = [(a, b) for f in CUBE_F for a, b in zip(f, f[1:] + f[:1])]
    m = sm.catmull_clark(CUBE_V, CUBE_F, 3, creases=edges)
    np.testing.assert_array_equal(m.vertices[:8], CUBE_V)
    on_face = np.any((np.abs(m.vertices) < 1e-15) | (np.abs(m.vertices - 1) < 1e-15), axis=1)
    assert on_face.all()
    assert m.to_trimesh().volume == pytest.approx(1.0, abs=1e-12)


def test_crease_curve_rule():
    # crease along the ring of four vertical-edge bottoms: 0-1-2-3 loop
    ring = [(0, 1), (1, 2), (2, 3), (3, 0)]
    out = sm.catmull_clark(CUBE_V, CUBE_F, 1, creases=ring)
    s = periodic_refinement(4)
    np.testing.assert_allclose(out.vertices[:4], (s @ CUBE_V[:4])[::2], atol=1e-15)
    lim = sm.catmull_clark_limit(CUBE_V, CUBE_F, creases=ring)
    deep = sm.catmull_clark(CUBE_V, CUBE_F, 7, creases=ring)
    np.testing.assert_allclose(lim.positions[:4], (CUBE_V[[3, 0, 1, 2]] + 4 * CUBE_V[:4] + CUBE_V[[1, 2, 3, 0]]) / 6)
    np.testing.assert_allclose(deep.vertices[:8], lim.positions, atol=2e-4)


# ---------------------------------------------------------------------------------------
# limit masks agree with many refinement levels
def fine_vertex_normals(m):
    t = m.to_trimesh()
    return np.asarray(t.vertex_normals)


@pytest.mark.parametrize("cage", ["cube", "prism", "open_box", "random_cube"])
def test_catmull_clark_limit_masks_converge(cage):
    if cage == "cube":
        v, f = CUBE_V, CUBE_F
    elif cage == "prism":
        v, f = pentagonal_prism()
    elif cage == "open_box":
        v, f = CUBE_V, CUBE_F[:5]
    else:
        v, f = CUBE_V + 0.15 * np.random.default_rng(3).standard_normal(CUBE_V.shape), CUBE_F
    lim = sm.catmull_clark_limit(v, f)
    errs = [np.abs(sm.catmull_clark(v, f, k).vertices[: len(v)] - lim.positions).max() for k in (3, 5, 7)]
    assert errs[2] < 3e-4 and errs[2] < errs[1] < errs[0]
    fine = sm.catmull_clark(v, f, 7)
    ok = np.isfinite(lim.normals[:, 0])
    assert ok.sum() >= 3
    cosines = np.einsum("ij,ij->i", fine_vertex_normals(fine)[: len(v)][ok], lim.normals[ok])
    assert np.all(cosines > np.cos(np.radians(0.5)))


def test_catmull_clark_limit_mask_at_regular_vertex_is_bspline():
    net, faces = torus_cage(jitter=0.2, seed=7)
    lim = sm.catmull_clark_limit(net.reshape(-1, 3), faces)
    wrap = lambda p: np.concatenate([p[-1:], p, p[:2]], 0)  # noqa: E731
    s = sm.BSplineSurface.uniform_cubic(wrap(wrap(net).transpose(1, 0, 2)).transpose(1, 0, 2))
    n, m = net.shape[:2]
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    np.testing.assert_allclose(lim.positions, s.points(i.ravel(), j.ravel()), atol=1e-13)
    np.testing.assert_allclose(lim.normals, s.normals(i.ravel(), j.ravel()), atol=1e-13)


@pytest.mark.parametrize("beta", ["loop", "warren"])
@pytest.mark.parametrize("cage", ["tet", "octahedron_open"])
def test_loop_limit_masks_converge(beta, cage):
    if cage == "tet":
        v, f = TET_V, TET_F
    else:
        v = np.array([(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)], float)
        f = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4), (1, 0, 5), (2, 1, 5), (3, 2, 5)]  # one face missing
    lim = sm.loop_limit(v, f, beta=beta)
    errs = [np.abs(sm.loop_subdivide(v, f, k, beta=beta).vertices[: len(v)] - lim.positions).max() for k in (3, 5, 7)]
    assert errs[2] < 1e-3 and errs[2] < errs[1] < errs[0]
    fine = sm.loop_subdivide(v, f, 7, beta=beta)
    ok = np.isfinite(lim.normals[:, 0])
    cosines = np.einsum("ij,ij->i", fine_vertex_normals(fine)[: len(v)][ok], lim.normals[ok])
    assert ok.sum() >= 1 and np.all(cosines > np.cos(np.radians(0.5)))


def test_loop_regular_limit_is_box_spline_mask():
    """Valence 6 with Loop's beta: limit = (6 v + sum e) / 12, beta = 1/16."""
    from surfmod.subdiv.loop import loop_beta

    assert loop_beta(6) == pytest.approx(1 / 16, abs=1e-16)
    assert loop_beta(3, "warren") == 3 / 16 and loop_beta(5, "warren") == 3 / 40
    ring = np.array([(np.cos(a), np.sin(a), 0.3 * np.sin(3 * a)) for a in np.arange(6) * np.pi / 3])
    v = np.concatenate([[[0, 0, 0.5]], ring])
    f = [(0, 1 + i, 1 + (i + 1) % 6) for i in range(6)]
    lim = sm.loop_limit(v, f)
    np.testing.assert_allclose(lim.positions[0], (6 * v[0] + ring.sum(0)) / 12, atol=1e-15)


# ---------------------------------------------------------------------------------------
# bad input
BAD = [
    (lambda: sm.catmull_clark(np.zeros((0, 3)), [[0, 1, 2]]), "vertices.*empty"),
    (lambda: sm.catmull_clark(CUBE_V, []), "faces.*empty"),
    (lambda: sm.catmull_clark(CUBE_V, np.zeros((0, 4), int)), "faces.*empty"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F + [(0, 1, 2, 3)] + [(1, 0, 6, 7)]), "faces.*non-manifold"),
    (lambda: sm.catmull_clark(CUBE_V, [(0, 1, 1, 2)] + CUBE_F[1:]), "faces.*repeats vertex 1"),
    (lambda: sm.catmull_clark(CUBE_V[:7], [(0, 1, 2, 3), (2, 4, 5, 6)]), "faces.*vertex 2 form 2 separate fans"),
    (lambda: sm.catmull_clark(CUBE_V, [(0, 3, 2, 8)] + CUBE_F[1:]), "faces.*out of range"),
    (lambda: sm.catmull_clark(CUBE_V, [(0, 3, 2, -1)] + CUBE_F[1:]), "faces.*out of range"),
    (lambda: sm.catmull_clark(CUBE_V, [(0, 1)] + CUBE_F[1:]), "faces.*at least 3"),
    (lambda: sm.catmull_clark(CUBE_V, [(0, 3.5, 2, 1)] + CUBE_F[1:]), "faces.*integers"),
    (lambda: sm.catmull_clark(CUBE_V, "abc"), "faces"),
    (lambda: sm.catmull_clark(np.where(np.eye(8, 3) > 0, np.nan, CUBE_V), CUBE_F), "vertices.*NaN"),
    (lambda: sm.catmull_clark(CUBE_V[:, :2], CUBE_F), "vertices.*last axis"),
    (lambda: sm.catmull_clark(np.vstack([CUBE_V, [[5, 5, 5]]]), CUBE_F), "vertices.*vertex 8 is used by no face"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 12), "levels.*limit"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 10**9), "levels.*limit"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, -1), "levels"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 1.5), "levels"),
    (lambda: sm.catmull_clark(*pentagonal_prism(), 0), "levels.*mixed"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 1, creases=[(0, 6)]), "creases.*0-6 is not an edge"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 1, creases=[(0, 1, 2)]), "creases"),
    (lambda: sm.catmull_clark(CUBE_V, CUBE_F, 1, creases=[(0, 9)]), "creases.*out of range"),
    (lambda: sm.loop_subdivide(CUBE_V, CUBE_F), "triangles.*expected 3"),
    (lambda: sm.loop_subdivide(TET_V, TET_F, 13), "levels.*limit"),
    (lambda: sm.loop_subdivide(TET_V, TET_F, 1, beta="stam"), "beta"),
    (lambda: sm.loop_subdivide(TET_V, [(0, 1, 1)] + TET_F[1:]), "triangles.*repeats"),
    (lambda: sm.loop_subdivide(np.full((4, 3), np.inf), TET_F), "vertices.*NaN or infinite"),
    (lambda: sm.loop_limit(TET_V, TET_F, beta="x"), "beta"),
    (lambda: sm.catmull_clark_limit(CUBE_V, [(0, 1, 9, 3)]), "faces.*out of range"),
]


@pytest.mark.parametrize("call, message", BAD, ids=[m for _, m in BAD])
def test_bad_input_is_refused_by_name(call, message):
    with pytest.raises(sm.SurfmodError, match=message):
        call()


def test_level_guard_estimate_is_the_face_count():
    """The guard's estimate (corners x 4^(levels-1)) is the exact face count."""
    m = sm.catmull_clark(*pentagonal_prism(), 2)
    assert len(m.faces) == 30 * 4
    assert tp.MAX_FACES == 20_000_000
    # 24 corners x 4^(11-1) = 25.2 M > 20 M is refused, 10 levels (6.3 M) would be allowed
    tp.levels_arg(10, 24)
    with pytest.raises(sm.SurfmodError, match="levels"):
        tp.levels_arg(11, 24)


# ---------------------------------------------------------------------------------------
# property: subdivision is affine invariant and its weights sum to one
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), scheme=st.sampled_from(["cc", "cc_prism", "cc_crease", "loop"]))
def test_subdivision_commutes_with_affine_maps(seed, scheme):
    rng = np.random.default_rng(seed)
    if scheme == "loop":
        v0, f = TET_V, TET_F
    elif scheme == "cc_prism":
        v0, f = pentagonal_prism()
    else:
        v0, f = CUBE_V, CUBE_F
    v = v0 + 0.2 * rng.standard_normal(v0.shape)
    a = rng.uniform(-2, 2, (3, 3)) + 3 * np.eye(3)
    b = rng.uniform(-5, 5, 3)
    creases = [(0, 1), (1, 2)] if scheme == "cc_crease" else None
    if scheme == "loop":
        run = lambda x: sm.loop_subdivide(x, f, 2).vertices  # noqa: E731
        lim = lambda x: sm.loop_limit(x, f).positions  # noqa: E731
    else:
        run = lambda x: sm.catmull_clark(x, f, 2, creases=creases).vertices  # noqa: E731
        lim = lambda x: sm.catmull_clark_limit(x, f, creases=creases).positions  # noqa: E731
    scale = np.abs(v @ a.T + b).max()
    np.testing.assert_allclose(run(v @ a.T + b), run(v) @ a.T + b, atol=1e-13 * scale)
    np.testing.assert_allclose(lim(v @ a.T + b), lim(v) @ a.T + b, atol=1e-13 * scale)


def test_loop_matches_trimesh_independent_implementation():
    # trimesh implements Loop's original rule on closed meshes: same vertex set, same count
    import trimesh
    from scipy.spatial import cKDTree
    from trimesh.remesh import subdivide_loop

    ico = trimesh.creation.icosphere(subdivisions=1)
    v, f = np.asarray(ico.vertices), np.asarray(ico.faces)
    ours = sm.loop_subdivide(v, f, levels=2)
    theirs, their_faces = subdivide_loop(v, f, iterations=2)
    assert ours.vertices.shape == theirs.shape and ours.faces.shape == their_faces.shape
    assert cKDTree(theirs).query(ours.vertices)[0].max() < 1e-14
    assert cKDTree(ours.vertices).query(theirs)[0].max() < 1e-14
