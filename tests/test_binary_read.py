"""Reading OCCT data through its binary serialization (BinTools) parsed by NumPy gives
exactly what reading item by item gives: BRepMesh triangulations
(``surfmod.occ.mesh._triangulation_table``: face for face, located copies of one face
sharing their entry) and B-spline surfaces (``surfmod.occ.geom.read_bspline_surface``:
poles, weights, flat knots, periodic ones unwrapped); bytes that do not follow the
expected layout are refused and the item-by-item path is taken."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.occ import geom as occ_geom
from surfmod.occ import mesh as occ_mesh
from tests.conftest import CORPUS


def _same(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return (np.array_equal(a.nodes, b.nodes) and np.array_equal(a.triangles, b.triangles)
            and np.array_equal(a.uv, b.uv, equal_nan=True) and a.reversed == b.reversed
            and a.deflection == b.deflection and a.rigid == b.rigid)


def _check_file(path, deflection):
    part = sm.import_step(path)
    meshed = occ_mesh.mesh_faces(part, deflection)
    for _, face, got in meshed:
        assert _same(got, occ_mesh.read_triangulation(face, True))
    return meshed


def test_binary_table_equals_node_by_node_on_an_assembly():
    # as1: 160 faces, located copies of 53 (bolts, nuts, plates), some with mirrored axes
    meshed = _check_file(CORPUS / "pythonocc_as1-oc-214.stp", 1.0)
    from OCP.TopLoc import TopLoc_Location

    groups = {}
    for _, face, got in meshed:
        groups.setdefault(got.instance, []).append(face.Located(TopLoc_Location()))
    assert len(groups) < len(meshed)  # copies share one entry ...
    for faces in groups.values():  # ... and only copies do
        assert all(f.IsSame(faces[0]) for f in faces)


def test_binary_table_equals_node_by_node_with_uv_and_splines():
    _check_file(CORPUS / "pythonocc_Ventilator.stp", 2.0)


@pytest.mark.corpus
def test_binary_table_equals_node_by_node_on_every_file(corpus_file):
    _check_file(corpus_file, 0.5)


def test_layout_mismatch_is_refused_and_mesh_faces_falls_back(monkeypatch):
    import build123d as bd

    box = bd.Box(1, 2, 3)
    good = occ_mesh.mesh_faces(box, 0.1)
    assert occ_mesh._parse_triangulations(b"Triangulations 1\n\x04\x00", 4) is None  # truncated
    assert occ_mesh._parse_triangulations(b"Polygon3D 0\n", 4) is None  # another section
    monkeypatch.setattr(occ_mesh, "_parse_triangulations", lambda data, version: None)
    fallback = occ_mesh.mesh_faces(box, 0.1)
    assert len(fallback) == len(good) == 6
    assert all(_same(a[2], b[2]) for a, b in zip(good, fallback))


def _same_surface_data(a, b) -> bool:
    return (a["degree"] == b["degree"] and np.array_equal(a["control_points"], b["control_points"])
            and all(np.array_equal(x, y) for x, y in zip(a["knots"], b["knots"]))
            and ((a["weights"] is None and b["weights"] is None) or np.array_equal(a["weights"], b["weights"])))


def _by_pole(surf):
    if surf.IsUPeriodic() or surf.IsVPeriodic():
        surf = surf.Copy()
        if surf.IsUPeriodic():
            surf.SetUNotPeriodic()
        if surf.IsVPeriodic():
            surf.SetVNotPeriodic()
    return occ_geom._read_bspline_surface_by_pole(surf)


def test_binary_bspline_surface_equals_pole_by_pole_rational_and_periodic():
    from surfmod.gallery.synthetic import wavy_net
    from surfmod.occ.topo import face_surface

    net = wavy_net(6, 5)
    weights = 1.0 + 0.5 * np.random.default_rng(3).random((6, 5))
    for surface in (sm.BSplineSurface(net, (3, 2)), sm.BSplineSurface(net, (2, 3), weights=weights)):
        occt = face_surface(surface.face())[0]
        got = occ_geom.read_bspline_surface(occt)
        assert _same_surface_data(got, _by_pole(occt))
        assert np.array_equal(got["control_points"], surface.control_points)
        assert (got["weights"] is None) == (surface.weights is None)
    periodic = face_surface(sm.BSplineSurface(net, (3, 2), weights=weights).face())[0].Copy()
    periodic.SetUPeriodic()
    got = occ_geom.read_bspline_surface(periodic)
    assert _same_surface_data(got, _by_pole(periodic))
    assert len(got["knots"][0]) == got["control_points"].shape[0] + got["degree"][0] + 1


def test_surface_layout_mismatch_is_refused():
    assert occ_geom._parse_bspline_surface(b"Surfaces 1\n\x09\x00") is None  # truncated
    assert occ_geom._parse_bspline_surface(b"Surfaces 1\n\x01" + bytes(96)) is None  # a plane


@pytest.mark.corpus
def test_binary_bspline_surface_equals_pole_by_pole_on_every_file(corpus_file):
    from OCP.BRep import BRep_Tool

    from surfmod.occ.topo import faces_of

    for face in faces_of(sm.import_step(corpus_file).wrapped):
        surf = occ_mesh.basis_surface(BRep_Tool.Surface_s(face))
        if occ_geom.surface_type(surf) == "Geom_BSplineSurface":
            assert _same_surface_data(occ_geom.read_bspline_surface(surf), _by_pole(surf))
