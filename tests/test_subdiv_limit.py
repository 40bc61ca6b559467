"""Catmull–Clark limit surfaces as CAD patches: exactness, measured continuity, OCCT solid."""

from __future__ import annotations

import numpy as np
import pytest

import reference as ref
import surfmod as sm
from surfmod.subdiv.limit import bezier_eval
from test_subdiv import CUBE_F, CUBE_V, pentagonal_prism, torus_cage


@pytest.fixture(scope="module")
def cube_limit():
    return sm.limit_surface(CUBE_V, CUBE_F)


@pytest.fixture(scope="module")
def cube_solid(cube_limit):
    return cube_limit.solid()


def test_regular_patches_are_the_uniform_cubic_bspline():
    """A torus cage is all regular: every patch is the lecture's matrix-form uniform
    cubic B-spline of its 4 x 4 neighbourhood, to 1e-12."""
    n, m = 6, 5
    net, faces = torus_cage(n, m, jitter=0.15, seed=2)
    lim = sm.limit_surface(net.reshape(-1, 3), faces, levels=0)
    assert lim.regular.all() and len(lim.patches) == n * m
    a = np.linspace(0, 1, 5)
    for f in (0, 7, 29):
        p, q = divmod(f, m)
        net4 = net[np.ix_(np.arange(p - 1, p + 3) % n, np.arange(q - 1, q + 3) % m)]
        patch = lim.patches[f]
        assert isinstance(patch, sm.BSplineSurface) and patch.domain == ((0.0, 1.0), (0.0, 1.0))
        np.testing.assert_array_equal(patch.control_points, net4)
        expected = np.array([[ref.uniform_cubic_point(net4, u, v) for v in a] for u in a])
        np.testing.assert_allclose(patch.grid(a, a), expected, atol=1e-12)
        # the Bézier form kept for measuring is the exact conversion
        uu, vv = (x.ravel() for x in np.meshgrid(a, a, indexing="ij"))
        bp, _ = bezier_eval(np.repeat(lim.bezier_nets[f][None], uu.size, 0), uu, vv)
        np.testing.assert_allclose(bp, expected.reshape(-1, 3), atol=1e-12)
    e = lim.errors
    assert e["max_gap"] < 1e-12 and e["max_normal_angle_deg"] < 1e-9
    assert e["max_limit_deviation"] < 1e-12 and e["max_limit_normal_deg"] < 1e-9


def test_acc_rules_reproduce_regular_patches(cube_limit):
    """On regular faces the extraordinary-patch rules give the B-spline's own Bézier
    points, so exact and approximate patches meet without a gap."""
    e = cube_limit.errors
    assert e["acc_regular_mismatch"] < 1e-14
    assert e["max_gap"] < 1e-12
    assert e["max_normal_angle_regular_deg"] < 1e-9
    assert e["max_limit_deviation_regular"] < 1e-12


def test_cube_limit_counts_and_corner_interpolation(cube_limit):
    lim = cube_limit
    assert len(lim.patches) == 96 and int(lim.regular.sum()) == 72 and lim.levels == 2
    assert all(isinstance(p, sm.BezierSurface) for p, r in zip(lim.patches, lim.regular) if not r)
    # patch corners are the exact limit points of the mesh vertices, with the exact
    # limit normal at the extraordinary vertices (tangent-plane projection)
    masks = sm.catmull_clark_limit(lim.mesh.vertices, lim.mesh.faces)
    quads = lim.mesh.faces
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    f = np.repeat(np.arange(len(quads)), 4)
    k = np.tile(np.arange(4), len(quads))
    p, nrm = bezier_eval(lim.bezier_nets[f], uv[k, 0], uv[k, 1])
    np.testing.assert_allclose(p, masks.positions[quads.ravel()], atol=1e-14)
    np.testing.assert_allclose(nrm, masks.normals[quads.ravel()], atol=1e-12)


def test_measured_errors_are_stated_and_shrink_with_levels():
    rng = np.random.default_rng(5)
    cage = CUBE_V + 0.1 * rng.standard_normal(CUBE_V.shape)
    errs = [sm.limit_surface(cage, CUBE_F, levels=k).errors for k in (1, 2, 3)]
    for e in errs:
        assert e["max_gap"] < 1e-12  # watertight by construction
        assert e["max_limit_deviation_regular"] < 1e-12
    dev = [e["max_limit_deviation_rel"] for e in errs]
    ang = [e["max_normal_angle_deg"] for e in errs]
    assert dev[2] < dev[1] < dev[0] < 0.01
    assert ang[2] < ang[1] < ang[0] < 4.0


def test_cube_solid_is_valid_closed_and_has_the_limit_volume(cube_solid):
    from OCP.BRepCheck import BRepCheck_Analyzer

    assert BRepCheck_Analyzer(cube_solid.wrapped).IsValid()
    assert len(cube_solid.faces()) == 96
    # volume of the polyhedron through exact limit points of a fine mesh (inscribed,
    # converges from below): the solid's volume must be just above it
    fine = sm.catmull_clark(CUBE_V, CUBE_F, 5)
    lim = sm.catmull_clark_limit(fine.vertices, fine.faces)
    poly = sm.Mesh(lim.positions, fine.faces).to_trimesh().volume
    assert poly < cube_solid.volume < poly * 1.002
    assert cube_solid.volume == pytest.approx(0.3275437, abs=2e-6)


def test_occt_measures_the_same_gap_and_normal_jump():
    """OCCT, through the p-curves of the sewn solid, sees the figures NumPy reported."""
    rng = np.random.default_rng(11)
    lim = sm.limit_surface(CUBE_V + 0.1 * rng.standard_normal(CUBE_V.shape), CUBE_F)
    occ = lim.occt_continuity()
    assert occ["shared_edges"] == 192
    assert occ["max_gap"] < 1e-12
    assert occ["max_normal_angle_deg"] == pytest.approx(lim.errors["max_normal_angle_deg"], abs=1e-9)


def test_adaptive_refinement_near_extraordinary_vertices():
    """Feature-adaptive levels: each extraordinary face becomes three exact patches and
    one smaller approximate one; the measured errors roughly halve per level."""
    errs = []
    for a in (0, 1, 2, 3):
        lim = sm.limit_surface(CUBE_V, CUBE_F, adaptive=a)
        assert len(lim.patches) == 96 + 72 * a and int((~lim.regular).sum()) == 24
        e = lim.errors
        assert e["max_gap"] < 1e-12 and e["max_limit_deviation_regular"] < 1e-12
        errs.append((e["max_normal_angle_deg"], e["max_limit_deviation_rel"], e["max_limit_normal_deg"]))
    for coarse, fine in zip(errs, errs[1:]):
        assert all(f < 0.7 * c for c, f in zip(coarse, fine))
    assert errs[3][0] < 0.1 and errs[3][1] < 3e-4


def test_adaptive_patches_sew_across_t_junctions():
    rng = np.random.default_rng(8)
    lim = sm.limit_surface(CUBE_V + 0.1 * rng.standard_normal(CUBE_V.shape), CUBE_F, levels=2, adaptive=2)
    solid = lim.solid()
    assert solid.is_valid and len(solid.faces()) == 240
    occ = lim.occt_continuity()
    assert occ["max_gap"] < 1e-12
    assert occ["max_normal_angle_deg"] == pytest.approx(lim.errors["max_normal_angle_deg"], abs=1e-9)
    # the same solid as without adaptive refinement, to the stated deviation
    coarse = sm.limit_surface(CUBE_V + 0.1 * np.random.default_rng(8).standard_normal(CUBE_V.shape), CUBE_F).solid()
    assert solid.volume == pytest.approx(coarse.volume, rel=2e-3)


def test_adaptive_on_open_creased_cage():
    lim = sm.limit_surface(CUBE_V, CUBE_F[:5], creases=[(0, 1), (1, 2)], adaptive=2)
    e = lim.errors
    assert lim.open and e["max_gap"] < 1e-12 and e["max_limit_deviation_regular"] < 1e-12
    assert e["max_limit_deviation_rel"] < 0.01
    assert len(lim.shell().faces()) == len(lim.patches)


def test_step_round_trip_faces_cross_check(cube_solid, tmp_path):
    path = tmp_path / "cube.step"
    sm.export_step(cube_solid, path)
    back = sm.import_step(path)
    faces = back.faces()
    assert len(back.solids()) == 1 and len(faces) == 96
    results = [sm.crosscheck(f, samples=6) for f in faces[::7]]
    assert all(r.passed and r.mode == "parametric" for r in results)
    assert max(r.max_deviation for r in results) < 1e-12


def test_patches_cross_check_against_occt(cube_limit):
    irregular = int(np.flatnonzero(~cube_limit.regular)[0])
    regular = int(np.flatnonzero(cube_limit.regular)[0])
    for f in (irregular, regular):
        r = sm.crosscheck(cube_limit.patches[f], samples=12)
        assert r.passed and r.mode == "parametric", r.details


def test_mixed_polygon_cage_becomes_a_solid():
    v, faces = pentagonal_prism()
    lim = sm.limit_surface(v, faces, levels=1)
    assert len(lim.patches) == 30 and lim.errors["max_gap"] < 1e-12
    shell = lim.shell()
    assert len(shell.faces()) == 30
    solid = lim.solid()
    assert solid.is_valid and solid.volume > 0
    fine = sm.catmull_clark(v, faces, 5)
    assert solid.volume == pytest.approx(sm.Mesh(fine.vertices, fine.faces).to_trimesh().volume, rel=0.02)


def open_grid(n=6, m=5):
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    z = np.sin(i * 0.9) * np.cos(j * 0.7)
    v = np.stack([i * 1.0, j * 1.2, z], -1)
    faces = np.array([[p * m + q, (p + 1) * m + q, (p + 1) * m + q + 1, p * m + q + 1] for p in range(n - 1) for q in range(m - 1)])
    return v, faces


def test_open_grid_is_exact_bspline_with_ghost_points():
    """Boundary curve rule and interpolated corners: every face of an open quad grid is an
    exact uniform cubic B-spline patch of the net continued by ghost points 2b - i."""
    net, faces = open_grid()
    lim = sm.limit_surface(net.reshape(-1, 3), faces, levels=0)
    assert lim.regular.all() and lim.open
    e = lim.errors
    assert e["max_limit_deviation"] < 1e-12 and e["max_limit_normal_deg"] < 1e-9
    assert e["max_gap"] < 1e-12 and e["max_normal_angle_deg"] < 1e-9
    # the whole grid continued by ghost rows/columns is one uniform cubic B-spline
    g = np.concatenate([2 * net[:1] - net[1:2], net, 2 * net[-1:] - net[-2:-1]], 0)
    g = np.concatenate([2 * g[:, :1] - g[:, 1:2], g, 2 * g[:, -1:] - g[:, -2:-1]], 1)
    whole = sm.BSplineSurface.uniform_cubic(g)
    a = np.linspace(0, 1, 4)
    m = net.shape[1]
    for f in (0, 3, 9, len(faces) - 1):
        p, q = divmod(f, m - 1)
        np.testing.assert_allclose(lim.patches[f].grid(a, a), whole.grid(p + a, q + a), atol=1e-12)
    # the corners are interpolated, the limit agrees with deep refinement
    np.testing.assert_allclose(whole.points(0.0, 0.0), net[0, 0], atol=1e-15)
    deep = sm.catmull_clark(net.reshape(-1, 3), faces, 6)
    np.testing.assert_allclose(deep.vertices[0], net[0, 0], atol=0)
    shell = lim.shell()
    assert len(shell.faces()) == len(faces)


def test_open_cage_with_extraordinary_vertices_gives_a_shell(tmp_path):
    lim = sm.limit_surface(CUBE_V, CUBE_F[:5])  # a box without one side
    e = lim.errors
    assert lim.open and e["boundary_edges"] == 16
    assert e["max_gap"] < 1e-12 and e["max_limit_deviation_regular"] < 1e-12
    assert e["max_limit_deviation_rel"] < 0.005 and e["max_normal_angle_deg"] < 2.0
    shell = lim.shell()
    assert len(shell.faces()) == 80
    assert type(lim.shape()).__name__ == "Shell"
    path = tmp_path / "open_box.step"
    sm.export_step(lim, path)  # a LimitSurface exports directly (its sewn shape)
    assert len(sm.import_step(path).faces()) == 80


def test_all_creases_give_the_flat_cube_exactly():
    edges = [(a, b) for f in CUBE_F for a, b in zip(f, f[1:] + f[:1])]
    lim = sm.limit_surface(CUBE_V, CUBE_F, levels=0, creases=edges)
    assert lim.regular.all() and len(lim.patches) == 6
    assert lim.errors["max_limit_deviation"] < 1e-14 and lim.errors["max_gap"] < 1e-14
    solid = lim.solid()
    assert solid.volume == pytest.approx(1.0, abs=1e-12)
    bb = solid.bounding_box()
    np.testing.assert_allclose([*bb.min, *bb.max], [0, 0, 0, 1, 1, 1], atol=1e-6)  # box has the face tolerance


def test_crease_through_regular_vertices_keeps_exact_patches():
    """A crease loop around a torus cage: its vertices follow the curve rule on both sides,
    so every patch is still an exact B-spline (continued by ghost points at the crease)."""
    n, m = 6, 5
    net, faces = torus_cage(n, m, jitter=0.1, seed=4)
    ring = [(p * m, ((p + 1) % n) * m) for p in range(n)]  # the edges j = 0 all around
    lim = sm.limit_surface(net.reshape(-1, 3), faces, levels=0, creases=ring)
    assert lim.regular.all()
    e = lim.errors
    assert e["max_limit_deviation"] < 1e-12 and e["max_gap"] < 1e-12
    assert e["max_normal_angle_deg"] < 1e-9  # smooth edges stay smooth
    # across the crease the normal jumps: the surface has a sharp edge there
    f0, f1 = 0, m - 1  # faces on both sides of the crease edge (0, m)
    n0 = lim.patches[f0].normals(0.5, 0.0)
    n1 = lim.patches[f1].normals(0.5, 1.0)
    np.testing.assert_allclose(lim.patches[f0].points(0.5, 0.0), lim.patches[f1].points(0.5, 1.0), atol=1e-12)
    assert np.degrees(np.arccos(np.clip(n0 @ n1, -1, 1))) > 5.0


def test_creased_cube_ring_is_a_valid_solid():
    ring = [(0, 1), (1, 2), (2, 3), (3, 0)]
    lim = sm.limit_surface(CUBE_V, CUBE_F, creases=ring)
    e = lim.errors
    assert e["max_gap"] < 1e-12 and e["max_limit_deviation_regular"] < 1e-12
    assert e["max_limit_deviation_rel"] < 0.005
    solid = lim.solid()
    assert solid.is_valid
    fine = sm.catmull_clark(CUBE_V, CUBE_F, 5, creases=ring)
    assert solid.volume == pytest.approx(fine.to_trimesh().volume, rel=0.01)


BAD = [
    (lambda: sm.limit_surface(CUBE_V, CUBE_F[:5]).solid(), "solid.*boundary"),
    (lambda: sm.limit_surface(CUBE_V, [CUBE_F[0][::-1]] + CUBE_F[1:]), "quads.*consistently oriented"),
    (lambda: sm.limit_surface(*pentagonal_prism(), levels=0), "quads.*levels=0"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, levels=9), "levels"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, levels=40), "levels.*limit"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, tangent_plane="yes"), "tangent_plane"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, adaptive=-1), "adaptive"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, adaptive=1.5), "adaptive"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, levels=3, adaptive=8), "adaptive.*too deep"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F, creases=[(0, 6)]), "creases.*not an edge"),
    (lambda: sm.limit_surface(CUBE_V, []), "quads.*empty"),
    (lambda: sm.limit_surface(CUBE_V, CUBE_F + [(0, 1, 5, 4)]), "quads.*non-manifold"),
    (lambda: sm.limit_surface(np.full((8, 3), np.nan), CUBE_F), "vertices.*NaN"),
    (lambda: sm.limit_surface(np.ones((8, 3)), CUBE_F), "vertices.*coincide"),
    (lambda: sm.limit_surface(CUBE_V, [(0, 3, 2, 2)] + CUBE_F[1:]), "quads.*repeats"),
    (lambda: sm.limit_surface(CUBE_V, [(0, 3, 2, 10)] + CUBE_F[1:]), "quads.*out of range"),
]


@pytest.mark.parametrize("call, message", BAD, ids=[m for _, m in BAD])
def test_limit_surface_bad_input(call, message):
    with pytest.raises(sm.SurfmodError, match=message):
        call()
