"""Adaptive tessellation: the measured deviation is a guarantee (checked independently
against OCCT), refinement follows curvature, closed surfaces and solids are watertight,
absurd tolerances are refused before allocating."""

from __future__ import annotations


import numpy as np
import pytest

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing import tessellate as tessellate_module
from surfmod.meshing.deviation import _barycentric
from surfmod.meshing.domain import domain_sides
from surfmod.occ.bindings import OCCT_VERSION
from surfmod.surface import model_size


def _independent_max_distance(s, mesh, per_triangle=3, limit=1500, seed=0):
    """Distance of random points on the triangles to the OCCT surface, measured by
    ``GeomAPI_ProjectPointOnSurf`` (not our Gauss-Newton)."""
    from surfmod.occ.sample import distances_to_surface

    rng = np.random.default_rng(seed)
    tri = mesh.vertices[mesh.triangles()]
    pick = rng.choice(len(tri), size=min(limit, len(tri)), replace=False)
    b = rng.dirichlet(np.ones(3), size=(len(pick), per_triangle))
    pts = np.einsum("tkj,tjd->tkd", b, tri[pick]).reshape(-1, 3)
    (u0, u1), (v0, v1) = s.domain
    d = distances_to_surface(s.geom(), pts, (u0, u1, v0, v1))
    return float(np.nanmax(d))


def _bspline():
    ku = [0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1]
    kv = [0, 0, 0, 0.3, 0.6, 1, 1, 1]
    return sm.BSplineSurface(wavy_net(7, 5), (3, 2), (ku, kv))


@pytest.mark.parametrize("method", ["grid", "adaptive"])
@pytest.mark.parametrize("tol", [0.05, 0.01])
def test_measured_deviation_is_within_tolerance_and_confirmed_by_occt(tol, method):
    s = _bspline()
    m = sm.tessellate(s, tol, method=method)
    assert m.info["kind"] == method
    assert 0 < m.info["max_deviation"] <= tol
    assert m.info["triangles"] == len(m.faces)
    # independent: OCCT's projection of random triangle points
    assert _independent_max_distance(s, m) <= tol * (1 + 1e-6)
    # vertices lie on the surface exactly (they are surface points)
    uv = m.info["uv"]
    np.testing.assert_allclose(m.vertices, s.points(uv[:, 0], uv[:, 1]), atol=1e-12)


def test_deviation_is_not_slack():
    """The reported maximum is a real maximum: close to the tolerance, not far below."""
    m = sm.tessellate(sm.BezierSurface(wavy_net(6, 5)), 0.01)
    assert 0.5 * 0.01 < m.info["max_deviation"] <= 0.01


def test_refinement_follows_curvature_cylinder_is_split_only_around():
    """A NURBS quarter-cylinder is straight along v: no cell is ever split along v."""
    w = np.sqrt(0.5)
    ring = np.array([[1, 0], [1, 1], [0, 1]], float) * 3.0
    net = np.array([[[x, y, 0.0], [x, y, 10.0]] for x, y in ring])
    s = sm.BSplineSurface(net, (2, 1), weights=np.array([[1, 1], [w, w], [1, 1]]))
    m = sm.tessellate(s, 1e-3)
    assert set(np.round(m.vertices[:, 2], 12)) == {0.0, 10.0}
    # sagitta of n equal chords of a quarter circle r=3: 3(1 - cos(pi/(4n))) <= 1e-3 -> n >= 31
    n_seg = len(np.unique(np.round(m.vertices[m.vertices[:, 2] == 0][:, :2], 9), axis=0)) - 1
    assert 31 <= n_seg <= 1.25 * 31
    assert m.info["max_deviation"] <= 1e-3


def test_refinement_is_local_where_curvature_is_high():
    """A flat net with one sharp bump: triangles crowd around the bump."""
    net = wavy_net(9, 9, amplitude=0.0)
    net[6, 6, 2] = 4.0
    s = sm.BSplineSurface(net, (3, 3))
    m = sm.tessellate(s, 0.005)
    c = m.vertices[m.triangles()].mean(axis=1)
    near = np.linalg.norm(c[:, :2] - net[6, 6, :2], axis=1) < 2.5
    area_near = np.pi * 2.5**2
    area_far = 80.0 - area_near
    assert near.sum() / area_near > 5 * (~near).sum() / area_far


def test_plane_needs_two_triangles():
    m = sm.tessellate(sm.plane((0, 0, 0), (3, 0, 0), (0, 2, 1)), 1e-6)
    assert len(m.faces) == 2 and m.info["max_deviation"] < 1e-12


def test_fewer_triangles_than_brepmesh_at_equal_tolerance():
    from surfmod.meshing.brep import DENSE, measure_face_meshes
    from surfmod.meshing.facemesh import brepmesh

    s = sm.BezierSurface(wavy_net(6, 5))
    ours = sm.tessellate(s, 0.01)
    fms = brepmesh(s.face(), 0.01)
    theirs = sum(len(f.triangles) for f in fms)
    assert len(ours.faces) <= theirs
    assert ours.info["max_deviation"] <= 0.01
    assert measure_face_meshes(fms, DENSE).max() > 0.005  # BRepMesh measured the same way


def test_sphere_surface_is_watertight_with_volume_bounds():
    r, tol = 2.0, 0.01
    m = sm.tessellate(sm.sphere(r), tol)
    tm = m.to_trimesh()
    assert tm.is_watertight and tm.is_winding_consistent
    # inscribed polyhedron: all vertices on the sphere, all facets within tol of it
    np.testing.assert_allclose(np.linalg.norm(m.vertices, axis=1), r, rtol=1e-13)
    assert 4 / 3 * np.pi * (r - tol) ** 3 <= tm.volume < 4 / 3 * np.pi * r**3
    assert m.info["max_deviation"] <= tol


def test_torus_closed_both_ways_is_watertight():
    m = sm.tessellate(sm.torus(3.0, 1.0), 0.02)
    tm = m.to_trimesh()
    assert m.info["closed"] == (True, True)
    assert tm.is_watertight and tm.is_winding_consistent
    assert abs(tm.volume) <= 2 * np.pi**2 * 3.0 * 1.0**2
    assert abs(tm.volume) >= 2 * np.pi**2 * 3.0 * (1.0 - 0.02) ** 2 * 0.99


def _teardrop(offset):
    """A profile leaving the axis ``offset`` from it and coming back onto it, revolved."""
    profile = sm.BSplineCurve([(offset, 0, 0), (1.2, 0, 0.3), (0.8, 0, 1.6), (0, 0, 1), (0, 0, 0)], 3)
    return sm.revolution(profile, (0, 0, 0), (0, 0, 1), 360.0)


@pytest.mark.parametrize("method", ["grid", "adaptive"])
@pytest.mark.parametrize("offset, sides", [(0.0, ({"v0", "v1"}, True, False)),  # two poles, one point
                                           (1.5e-9, ({"v1"}, True, True))])     # v1 collapsed and closed
def test_both_meshers_share_seams_and_poles_where_a_side_is_closed_and_collapsed(method, offset, sides):
    """The pole and seam vertices of both meshers come from one rule
    (``domain.shared_points``): a start 1.5e-9 off the axis makes ``v`` closed while only
    ``v1`` collapses, and closing before collapsing keeps the mesh watertight there (the
    grid's own rule, collapsing first, left the seam open)."""
    s = _teardrop(offset)
    deg, cu, cv = domain_sides(s, model_size(s, samples=17))
    assert ({k for k, d in deg.items() if d}, cu, cv) == sides
    m = sm.tessellate(s, 0.01, method=method)
    assert m.edge_use() == (True, True)
    if offset == 0.0:  # one vertex per pole, not a ring
        assert np.count_nonzero(np.linalg.norm(m.vertices, axis=1) <= 1e-12) == 2


def test_closed_solid_is_watertight_outward_and_within_tolerance():
    import build123d as bd

    from surfmod.occ.sample import distances_to_face
    from surfmod.occ.topo import faces_of

    hole = bd.Solid.make_cylinder(2, 10).moved(bd.Location((5, 5, 0)))
    solid = bd.fillet(bd.Solid.make_box(10, 10, 10).edges(), 2) - hole
    tol = 0.01
    m = sm.tessellate(solid, tol)
    tm = m.to_trimesh()
    assert tm.is_watertight and tm.is_winding_consistent
    assert tm.volume > 0  # outward normals
    assert abs(tm.volume - solid.volume) < 1e-2 * solid.volume
    assert m.info["max_deviation"] <= tol
    # independent: distance of triangle centroids to the nearest face (BRepExtrema)
    c = m.vertices[m.triangles()].mean(axis=1)[:: max(1, len(m.faces) // 150)]
    d = np.min([distances_to_face(f, c) for f in faces_of(solid)], axis=0)
    assert d.max() <= tol * (1 + 1e-6)


def test_sample_points_exclude_corners():
    b = _barycentric(4)
    assert len(b) == 12 and np.allclose(b.sum(axis=1), 1) and not np.any(b == 1)


# -- bad input ----------------------------------------------------------------------------
@pytest.mark.parametrize("tol", [0, -1.0, float("nan"), float("inf"), "abc", None])
def test_bad_tolerance(tol):
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.tessellate(sm.sphere(1.0), tol)


def test_absurdly_small_tolerance_is_refused_before_meshing():
    # the triangle count is estimated from curvature bounds first: no mesh is ever built
    with pytest.raises(sm.SurfmodError, match="tolerance.*triangles"):
        sm.tessellate(sm.sphere(1.0), 1e-8)
    with pytest.raises(sm.SurfmodError, match="tolerance.*below"):
        sm.tessellate(sm.sphere(1.0), 1e-13)
    import build123d as bd

    with pytest.raises(sm.SurfmodError, match="tolerance.*triangles"):
        sm.tessellate(bd.Solid.make_sphere(10), 1e-6)


def test_max_triangles_limit():
    with pytest.raises(sm.SurfmodError, match="max_triangles"):
        sm.tessellate(sm.sphere(1.0), 1e-4, max_triangles=1000)
    with pytest.raises(sm.SurfmodError, match="max_triangles"):
        sm.tessellate(sm.sphere(1.0), 1e-2, max_triangles=0)


@pytest.mark.parametrize("obj", ["sphere", 3.0, None])
def test_bad_object(obj):
    with pytest.raises(sm.SurfmodError, match="obj"):
        sm.tessellate(obj, 0.1)


def test_mesh_is_refused():
    with pytest.raises(sm.SurfmodError, match="obj.*Mesh"):
        sm.tessellate(sm.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]), 0.1)


def test_solid_whose_model_is_off_by_more_than_the_tolerance_is_reported_or_refused_when_strict():
    """A near-tangent boolean leaves edges with 0.056 tolerance: BRepMesh discretizes no
    edge finer than that, so a spherical corner stays 0.025 off whatever the deflection
    (one on OCCT 7.9; OCCT 8.0's boolean leaves two such corners).  The mesh is written
    (watertight) and those faces are reported with their own tolerance; ``strict`` refuses
    instead."""
    import build123d as bd

    from surfmod.meshing.brep import DENSE, measure_face
    from surfmod.meshing.facemesh import brepmesh
    from surfmod.occ.sample import distances_to_face
    from surfmod.occ.topo import faces_of

    solid = bd.fillet(bd.Solid.make_box(10, 10, 10).edges(), 2) - bd.Solid.make_cylinder(2, 10)
    m = sm.tessellate(solid, 0.01)
    assert m.to_trimesh().is_watertight
    over = m.info["faces_over_tolerance"]
    assert len(over) == (2 if OCCT_VERSION >= (8, 0) else 1)
    for face in over:
        assert face["surface"] == "SphericalSurface"
        assert 0.01 < face["deviation"] <= face["model_tolerance"] and face["model_tolerance"] > 0.05
    face = max(over, key=lambda f: f["deviation"])
    assert m.info["max_deviation"] == face["deviation"]
    # the reported deviation is real: OCCT's distance from the worst triangle's samples
    # to that face (BRepExtrema) agrees with the measurement
    (fm,) = [f for f in brepmesh(solid, m.info["deflection"]) if f.index == face["face"]]
    per_triangle, _ = measure_face(fm, 0.0)
    worst = fm.nodes[fm.triangles[np.argmax(per_triangle)]]
    occt = distances_to_face(faces_of(solid)[face["face"]], DENSE @ worst)
    assert occt.max() == pytest.approx(face["deviation"], rel=1e-6)
    with pytest.raises(sm.SurfmodError, match=rf"(?s)tolerance: 0.01 is not met on {len(over)} faces?.*strict.*model "
                                              r"tolerance 0.056"):
        sm.tessellate(solid, 0.01, strict=True)


def test_ear_clipping_never_collapses_onto_a_side():
    """Regression: a cell with two hanging nodes on one side, whose greedy clipping used to
    leave four collinear points; every triangle must keep an area and they tile the cell."""
    from surfmod.meshing.adaptive import ear_clip

    poly = np.array([[16, 4], [20, 4], [20, 5], [20, 6], [20, 8], [16, 8]], dtype=np.int64)
    pos = np.array(
        [
            [1.8356333839, 1.6011877367, -0.1847333487],
            [2.5320718870, 1.4639773194, -0.0758561436],
            [2.5142981986, 1.5497472086, -0.0929060905],
            [2.5010203188, 1.6186577909, -0.1062807071],
            [2.4769170899, 1.7568772270, -0.1245615055],
            [1.8424589576, 2.0931728884, -0.1520255821],
        ]
    )
    tris = ear_clip(poly, pos)
    assert tris.shape == (4, 3, 2)
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    assert np.all(cross > 0) and cross.sum() == 2 * 16


@pytest.mark.parametrize("seed", [2, 6, 11])
def test_random_splines_with_creases_and_collapsed_edges(seed):
    """Random nets, degrees 1-4, interior knots up to multiplicity 2, rational or not,
    some with a collapsed edge: measured deviation within tolerance, mesh valid."""
    rng = np.random.default_rng(seed)
    p, q = rng.integers(1, 5, 2)
    n, m = p + rng.integers(1, 4), q + rng.integers(1, 4)
    net = rng.uniform(-1, 1, (n, m, 3))
    net[..., 0] += 2 * np.arange(n)[:, None]
    net[..., 1] += 2 * np.arange(m)[None, :]

    def kv(nc, d):
        inner = np.sort(rng.uniform(0.1, 0.9, nc - d - 1))
        if inner.size > 1 and d > 1:
            inner[1] = inner[0]
        return np.concatenate([np.zeros(d + 1), inner, np.ones(d + 1)])

    if seed == 6:
        net[0, :, :] = net[0, 0]
    w = rng.uniform(0.3, 3, (n, m)) if seed != 2 else None
    s = sm.BSplineSurface(net, (p, q), (kv(n, p), kv(m, q)), w)
    m_ = sm.tessellate(s, 0.02)
    assert m_.info["max_deviation"] <= 0.02
    f = m_.faces
    assert np.all((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2]))


# -- the structured grid (default for smooth surfaces) ---------------------------------------
def _weighted_nurbs():
    w = np.ones((6, 6))
    w[2:4, 2:4] = 4.0
    w[0, :] = 0.5
    return sm.BSplineSurface(wavy_net(6, 6), (3, 3), weights=w)


def _sphere_distance(p):
    return np.abs(np.linalg.norm(p, axis=-1) - 5.0)


def _torus_distance(p):
    return np.abs(np.hypot(np.hypot(p[..., 0], p[..., 1]) - 8.0, p[..., 2]) - 2.0)


@pytest.mark.parametrize(
    "make, closed_form",
    [(_weighted_nurbs, None), (lambda: sm.sphere(5.0), _sphere_distance), (lambda: sm.torus(8.0, 2.0), _torus_distance)],
)
def test_grid_reported_maximum_is_the_measured_one(make, closed_form):
    """The 25 samples of every triangle (the measurement BRepMesh gets in the benchmark),
    measured by the closed-form distance (sphere, torus) or projected by Gauss-Newton
    (NURBS), give the reported maximum: it is neither exceeded nor slack, and OCCT's own
    projection of random triangle points stays within it."""
    from surfmod.meshing.deviation import DENSE, triangle_deviations

    s, tol = make(), 0.01
    m = sm.tessellate(s, tol, method="grid")
    assert m.info["kind"] == "grid"
    tri = m.vertices[m.faces]
    if closed_form is None:
        (u0, u1), (v0, v1) = s.domain
        uv = m.info["uv"][m.faces]
        full = triangle_deviations(lambda u, v: s._derivatives(u, v, 1), tri, uv, (u0, u1, v0, v1), DENSE)
    else:
        full = closed_form(np.einsum("kj,tjd->tkd", DENSE, tri)).max(axis=1)
    assert full.max() <= m.info["max_deviation"] * (1 + 1e-9) <= tol * (1 + 1e-9)
    assert full.max() >= 0.999 * m.info["max_deviation"]
    np.testing.assert_allclose(m.vertices, s.points(m.info["uv"][:, 0], m.info["uv"][:, 1]), atol=1e-12)
    if closed_form is None:
        assert _independent_max_distance(s, m) <= tol * (1 + 1e-6)


def test_grid_keeps_creases_as_lines():
    """A double knot of a quadratic is a crease (C0): it is a grid line, so no triangle
    straddles it."""
    net = wavy_net(6, 4)
    net[2:, :, 2] += 1.5  # a step: the crease at the double knot u = 0.5
    s = sm.BSplineSurface(net, (2, 2), ([0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1], [0, 0, 0, 0.5, 1, 1, 1]))
    m = sm.tessellate(s, 0.01, method="grid")
    assert 0.5 in set(m.info["uv"][:, 0])
    u = m.info["uv"][m.faces][..., 0]
    assert not np.any((u.min(axis=1) < 0.5) & (u.max(axis=1) > 0.5))
    assert m.info["max_deviation"] <= 0.01


def test_grid_torus_matches_the_closed_form_count():
    """On a torus every v-edge is a chord of a tube circle (radius r) and the u-edges
    of the outer equator are chords of a circle of radius R + r: each count is at least
    the number of chords whose sagitta alone is the tolerance.  On the outer equator
    both directions bend the same way and a triangle's interior sags by the sum of both
    chords' sagittas: a uniform grid giving each half the tolerance needs sqrt(2) times
    both counts; the placed grid (denser on the outside only) needs no more cells."""
    big, small, tol = 8.0, 2.0, 0.01
    m = sm.tessellate(sm.torus(big, small), tol, method="grid")
    uv = m.info["uv"]
    n_u, n_v = len(np.unique(uv[:, 0])), len(np.unique(uv[:, 1]))  # closed: lines = chords
    need_v = np.pi / np.arccos(1 - tol / small)  # chords whose sagitta alone is tol
    need_u = np.pi / np.arccos(1 - tol / (big + small))
    assert n_v >= need_v and n_u >= need_u
    assert n_u * n_v <= 2 * need_u * need_v
    tm = m.to_trimesh()
    assert tm.is_watertight and tm.is_winding_consistent


def test_grid_that_cannot_meet_the_tolerance_raises():
    """Issue 15: never a mesh over the tolerance.  The curvature estimate lets 300
    triangles through, the verified grid needs more: refused, naming the limit."""
    with pytest.raises(sm.SurfmodError, match=r"tolerance: 0.01 needs more than 300 triangles.*max_triangles"):
        sm.tessellate(sm.BezierSurface(wavy_net(6, 5)), 0.01, method="grid", max_triangles=300)


def test_auto_refines_locally_around_an_isolated_feature():
    net = wavy_net(9, 9, amplitude=0.0)
    net[6, 6, 2] = 4.0
    s = sm.BSplineSurface(net, (3, 3))
    auto, grid = sm.tessellate(s, 0.01), sm.tessellate(s, 0.01, method="grid")
    assert auto.info["kind"] == "adaptive" and len(auto.faces) < len(grid.faces)
    assert sm.tessellate(_weighted_nurbs(), 0.01).info["kind"] == "grid"


@pytest.mark.parametrize("method", ["fast", 3, None])
def test_bad_method(method):
    with pytest.raises(sm.SurfmodError, match="method"):
        sm.tessellate(sm.sphere(1.0), 0.1, method=method)


def test_tiny_tolerance_refused_before_meshing(monkeypatch):
    """Issue 25: a creased superellipsoid at 3e-6 was refused only after ~28 s of
    refinement; the curvature estimate times the fewest triangles any mesh took per
    estimated one (MESH_OVERHEAD) refuses it before a grid or a cell is built."""
    from surfmod.meshing import adaptive

    def never(*args, **kwargs):
        raise AssertionError("meshing started before the refusal")

    monkeypatch.setattr(adaptive.Refiner, "run", never)
    monkeypatch.setattr(tessellate_module, "grid_tessellate", never)
    s = sm.superellipsoid(1, 1, 1, 1.8, 1.8)
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: 3e-06 would need about [\d,]+ triangles.*max_triangles=250,000"):
        sm.tessellate(s, 3e-6)


def test_refinement_refuses_as_soon_as_its_fewest_cells_pass_the_cap(monkeypatch):
    """Before each split the refinement counts the fewest cells it can end with (a split
    cuts a cell's sag at best fourfold): over the cap it refuses then, not once the cells
    themselves are over it."""
    from surfmod.meshing import adaptive

    sizes = []
    original = adaptive.Refiner.split

    def split(self, cells):
        sizes.append(self.x0.size)
        return original(self, cells)

    monkeypatch.setattr(adaptive.Refiner, "split", split)
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: 0.0001 needs more than [\d,]+ triangles.*found after"):
        sm.tessellate(sm.superellipsoid(1, 1, 1, 1.8, 1.8), 1e-4, method="adaptive", max_triangles=20_000)
    assert all(2 * n <= 20_000 for n in sizes)  # never built more cells than the cap allows
