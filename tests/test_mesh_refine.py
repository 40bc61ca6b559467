"""Refining a face's BRepMesh triangulation inside its boundary (surfmod.meshing.refine),
and one measurement per isometric repeat of a face: the STL stays watertight, every new
triangle is measured, and BRepMesh runs once where it used to run twice."""

from __future__ import annotations

import numpy as np
import pytest
from stlcheck import ADMESH_REPAIRS, admesh_stats, needs_admesh
from test_corpus_mesh import closed_and_oriented

import surfmod as sm
from surfmod.meshing.brep import measure_face
from surfmod.meshing.refine import split_round
from surfmod.meshing.figures import shape_diagonal
from surfmod.meshing.facemesh import brepmesh


@pytest.fixture(scope="module")
def ventilator(corpus_dir):
    """pythonocc_Ventilator.stp (2.2 MB), read once for the tests of this module that
    measure it: none changes it (brepmesh clears the triangulations it finds)."""
    return sm.import_step(corpus_dir / "pythonocc_Ventilator.stp")


def _boundary_edges(tri):
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    return {tuple(x) for x in edges[counts == 1]}


def _signed_areas(uv, tri):
    a, b, c = uv[tri[:, 0]], uv[tri[:, 1]], uv[tri[:, 2]]
    return 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])


def test_split_round_keeps_boundary_orientation_and_area():
    rng = np.random.default_rng(4)
    g = np.stack(np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), indexing="ij"), -1).reshape(-1, 2)
    g[:, 0] += 0.02 * rng.standard_normal(len(g)) * (g[:, 0] % 1 > 0) * (g[:, 1] % 1 > 0)
    quads = np.array([[i * 4 + j, (i + 1) * 4 + j, (i + 1) * 4 + j + 1, i * 4 + j + 1] for i in range(4) for j in range(3)])
    tri = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])

    def surface(uv):
        return np.c_[uv, np.sin(3 * uv[:, 0]) * np.cos(2 * uv[:, 1])]

    nodes, uv = surface(g), g
    boundary = _boundary_edges(tri)
    area = _signed_areas(uv, tri).sum()
    for bad in (np.arange(len(tri)) % 3 == 0, np.ones(len(tri), bool)):
        nodes, uv, new_tri, kept = split_round(nodes, uv, tri, np.resize(bad, len(tri)), surface)
        assert _boundary_edges(new_tri) == boundary  # no split on the boundary: neighbours still match
        assert np.all(_signed_areas(uv, new_tri) > 0)  # orientation kept, nothing folded
        assert _signed_areas(uv, new_tri).sum() == pytest.approx(area, rel=1e-14)
        assert np.abs(nodes - surface(uv)).max() < 1e-15  # new nodes on the surface
        assert np.array_equal(new_tri[: len(kept)], tri[kept])
        assert len(new_tri) > len(tri)
        tri = new_tri


def test_centroid_split_of_a_triangle_without_interior_edge():
    uv = np.array([[0.0, 0], [1, 0], [0, 1]])
    nodes, uv2, tri, kept = split_round(np.c_[uv, np.zeros(3)], uv, np.array([[0, 1, 2]]), np.array([True]),
                                        lambda q: np.c_[q, q[:, 0] * q[:, 1]])
    assert kept.size == 0 and tri.tolist() == [[0, 1, 3], [1, 2, 3], [2, 0, 3]]
    np.testing.assert_allclose(nodes[3], [1 / 3, 1 / 3, 1 / 9], rtol=0, atol=1e-16)


@needs_admesh
def test_overshooting_cone_is_refined_in_one_brepmesh_pass(corpus_dir, tmp_path):
    """BRepMesh at the tolerance leaves the countersink cone of the M6 screw 15 % over
    it; that face alone is refined, the STL is watertight with no admesh repair and
    within the tolerance by OCCT's own distance."""
    step = corpus_dir / "build123d_M6-1x12-countersunk-screw.step"
    shape = sm.import_step(step)
    tol = 1e-3 * shape_diagonal(shape)
    (cone,) = [fm for fm in brepmesh(shape, tol) if fm.index == 3]
    assert measure_face(cone, tol)[0].max() > 1.1 * tol  # what BRepMesh gives
    out = tmp_path / "m6.stl"
    mesh = sm.export_stl(shape, out, tol)
    assert mesh.info["attempts"] == 1 and mesh.info["locally_refined_faces"] == 1
    assert mesh.info["max_deviation"] <= tol and not mesh.info["faces_over_tolerance"]
    assert closed_and_oriented(out)
    st = admesh_stats(out)
    assert all(st[k] == 0 for k in ADMESH_REPAIRS), st



def test_refined_cone_is_within_tolerance_by_occt_distance(corpus_dir):
    """The refined face checked by OCCT's own distance to the face (not surfmod's)."""
    from surfmod.meshing.brep import _refine_locally
    from surfmod.meshing.deviation import DENSE
    from surfmod.occ.sample import distances_to_face

    shape = sm.import_step(corpus_dir / "build123d_M6-1x12-countersunk-screw.step")
    tol = 1e-3 * shape_diagonal(shape)
    fms = brepmesh(shape, tol)
    (i,) = [k for k, fm in enumerate(fms) if fm.index == 3]
    dev, node_dev = np.zeros(len(fms)), np.zeros(len(fms))
    before = len(fms[i].triangles)
    assert _refine_locally(fms, i, dev, node_dev, tol)
    fm = fms[i]
    assert len(fm.triangles) > before and 0 < dev[i] <= tol
    pts = np.einsum("kj,tjd->tkd", DENSE, fm.nodes[fm.triangles]).reshape(-1, 3)
    assert distances_to_face(fm.face, pts).max() <= tol * (1 + 1e-9)


def test_isometric_repeats_have_the_deviation_of_their_first_instance(corpus_dir):
    shape = sm.import_step(corpus_dir / "pythonocc_as1-oc-214.stp")
    tol = 1e-3 * shape_diagonal(shape)
    fms = brepmesh(shape, tol)
    repeats = [fm for fm in fms if fm.repeats >= 0]
    assert len(repeats) > 50  # 160 faces, 53 distinct
    for fm in repeats[:: max(1, len(repeats) // 12)]:
        first = fms[fm.repeats]
        assert not np.array_equal(fm.nodes, first.nodes)  # somewhere else in space
        d, nd = measure_face(fm, tol)
        d0, nd0 = measure_face(first, tol)
        assert d.max() == pytest.approx(d0.max(), rel=1e-9, abs=1e-12 * tol)
        assert nd == pytest.approx(nd0, rel=1e-9, abs=1e-12 * tol)


def test_spline_figures_in_one_pass_equal_geomlprop(ventilator):
    """The triangle estimate samples B-spline faces with surfmod's evaluator (all faces'
    curvatures at once) and gets what GeomLProp, face by face, gives."""
    from surfmod.meshing.brep import triangle_estimate

    part = ventilator
    evaluators: dict = {}
    for tolerance in (0.05, 0.5):
        by_occt, diag = triangle_estimate(part, tolerance)
        ours, same_diag = triangle_estimate(part, tolerance, evaluators)
        assert same_diag == diag
        assert ours == pytest.approx(by_occt, rel=1e-6)
    assert len(evaluators) == 189 + 26  # every B-spline face and extrusion, kept for measuring


def test_estimate_figures_equal_geomlprop(ventilator):
    """Cones and tori get the estimate's figures from their radii in closed form, swept
    surfaces from their surfmod evaluators' partials: the same numbers GeomLProp's
    samples give (5 x 5, or 3 columns x 5 rows where only v matters; no curvature at an
    apex)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.GeomLProp import GeomLProp_SLProps

    from surfmod.meshing import figures
    from surfmod.occ import mesh as occ_mesh
    from surfmod.occ.geom import surface_type
    from surfmod.occ.topo import faces_of

    shape = ventilator.wrapped
    floor = 1.0 / shape_diagonal(shape)
    seen = set()
    for face in faces_of(shape):
        surf = occ_mesh.face_basis(face)
        name = surface_type(surf)
        if name not in ("Geom_ConicalSurface", "Geom_ToroidalSurface", "Geom_SurfaceOfRevolution",
                        "Geom_SurfaceOfLinearExtrusion"):
            continue
        seen.add(name)
        area, k = figures._face_figure(face, 5, floor)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        props, jac, vals = GeomLProp_SLProps(surf, 2, 1e-9), [], []
        for u in np.linspace(u0, u1, 3 if name in ("Geom_ConicalSurface", "Geom_ToroidalSurface") else 5):
            for v in np.linspace(v0, v1, 5):
                props.SetParameters(float(u), float(v))
                jac.append(props.D1U().Crossed(props.D1V()).Magnitude())
                if props.IsCurvatureDefined():
                    vals.append(np.sqrt(max(abs(props.MaxCurvature()), floor) * max(abs(props.MinCurvature()), floor)))
        assert area == pytest.approx(np.mean(jac) * (u1 - u0) * (v1 - v0), rel=1e-12)
        assert k == pytest.approx(np.median(vals) if vals else floor, rel=1e-12)
    assert seen == {"Geom_ConicalSurface", "Geom_ToroidalSurface", "Geom_SurfaceOfRevolution",
                    "Geom_SurfaceOfLinearExtrusion"}


def test_spline_faces_measured_in_one_call_equal_face_by_face(ventilator):
    """measure_spline_faces (every B-spline face of a part in one compiled call) gives
    each face the triangle and node deviations measure_face gives it alone, in NumPy
    (each face's samples are below COMPILED_MEASURE), to the round-off of the samples'
    coordinates: the compiled measure and its NumPy twin agree."""
    from surfmod.meshing.brep import COMPILED_MEASURE, _bounds, _evaluator, _samples, measure_spline_faces
    from surfmod.meshing.deviation import DENSE, triangle_deviations

    shape = ventilator
    tol = 1e-3 * shape_diagonal(shape)
    fms = brepmesh(shape, tol)
    evaluators: dict = {}
    pairs = [(fm, ev) for fm in fms if (ev := _evaluator(evaluators, fm)) is not None and ev.projector is not None]
    assert len(pairs) > 150  # B-spline faces and extrusions of B-spline curves
    assert max(_samples([fm], DENSE) for fm, _ in pairs) < COMPILED_MEASURE  # alone, each in NumPy
    together = measure_spline_faces([fm for fm, _ in pairs], [ev for _, ev in pairs], tol)
    for k, ((fm, ev), (tri, node)) in enumerate(zip(pairs, together)):
        alone_tri, alone_node = measure_face(fm, tol, ev=ev)
        np.testing.assert_allclose(tri, alone_tri, rtol=1e-12, atol=1e-12 * tol)
        assert node == pytest.approx(alone_node, rel=1e-12, abs=1e-12 * tol)
        if k % 10 == 0:  # and the NumPy Gauss-Newton iteration gives the same bounds
            box = _bounds(fm, ev)
            by_numpy = triangle_deviations(ev.d1, fm.nodes[fm.triangles], fm.uv[fm.triangles], box, DENSE,
                                           0.5 * tol, ev.d0, accurate_max=False)
            np.testing.assert_allclose(tri, by_numpy, rtol=1e-9, atol=1e-12 * tol)


def test_analytic_faces_measured_at_once_equal_face_by_face(ventilator):
    """measure_analytic_faces (every plane, cylinder, cone and torus face of a part in
    one compiled pass) gives each face what measure_face gives it alone."""
    from surfmod.meshing import analytic_distance as analytic
    from surfmod.meshing.brep import measure_analytic_faces

    shape = ventilator
    tol = 1e-3 * shape_diagonal(shape)
    pairs = [(fm, a) for fm in brepmesh(shape, tol) if (a := analytic.parameters(fm.surface)) is not None]
    assert len({a[0] for _, a in pairs}) == 4  # planes, cylinders, cones and tori
    together = measure_analytic_faces([fm for fm, _ in pairs], [a for _, a in pairs])
    for (fm, _), (tri, node) in zip(pairs, together):
        alone_tri, alone_node = measure_face(fm, tol)
        np.testing.assert_allclose(tri, alone_tri, rtol=1e-12, atol=1e-12 * tol)
        assert node == pytest.approx(alone_node, rel=1e-12, abs=1e-12 * tol)
