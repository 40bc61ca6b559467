"""STL for CAM: a closed solid exports watertight and manifold, tolerance-driven, in
binary and ASCII; read back with trimesh and with a real STL client (Debian ``admesh``)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import surfmod as sm
from stlcheck import ADMESH_REPAIRS as _ADMESH_REPAIRS
from stlcheck import admesh_stats as _admesh_stats


def _solid():
    import build123d as bd

    hole = bd.Solid.make_cylinder(2, 10).moved(bd.Location((5, 5, 0)))
    return bd.fillet(bd.Solid.make_box(10, 10, 10).edges(), 1.5) - hole


def _load(path):
    import trimesh

    return trimesh.load(str(path), file_type="stl", process=True)


@pytest.mark.parametrize("ascii", [False, True])
def test_solid_stl_is_watertight_manifold_and_outward(tmp_path, ascii):
    solid = _solid()
    path = tmp_path / ("s_ascii.stl" if ascii else "s.stl")
    m = sm.export_stl(solid, path, tolerance=0.01, ascii=ascii)
    assert m.info["max_deviation"] <= 0.01
    tm = _load(path)
    assert tm.is_watertight and tm.is_winding_consistent
    # manifold: every edge has exactly two faces
    edges = np.sort(tm.edges, axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    assert len(tm.faces) == len(m.faces)
    assert tm.volume > 0 and abs(tm.volume - solid.volume) < 5e-3 * solid.volume
    head = path.read_bytes()[:5]
    assert (head == b"solid") == ascii


def test_tolerance_drives_the_facet_count(tmp_path):
    a = sm.export_stl(_solid(), tmp_path / "a.stl", tolerance=0.1)
    b = sm.export_stl(_solid(), tmp_path / "b.stl", tolerance=0.005)
    assert len(b.faces) > 3 * len(a.faces)
    assert a.info["max_deviation"] <= 0.1 and b.info["max_deviation"] <= 0.005


def test_surfmod_sphere_exports_watertight(tmp_path):
    m = sm.export_stl(sm.sphere(3.0), tmp_path / "sphere.stl", tolerance=0.01)
    tm = _load(tmp_path / "sphere.stl")
    assert tm.is_watertight and tm.is_winding_consistent and tm.volume > 0
    assert m.info["kind"] in ("grid", "adaptive") and m.info["max_deviation"] <= 0.01  # surfmod's own mesher


@pytest.mark.skipif(shutil.which("admesh") is None, reason="admesh not installed (apt-get install admesh)")
@pytest.mark.parametrize("ascii", [False, True])
def test_admesh_finds_nothing_to_fix(tmp_path, ascii):
    solid = _solid()
    path = tmp_path / "part.stl"
    m = sm.export_stl(solid, path, tolerance=0.01, ascii=ascii)
    st = _admesh_stats(path)
    assert st["Number of facets"] == len(m.faces)
    for key in _ADMESH_REPAIRS:
        assert st[key] == 0, (key, st)
    assert st["Number of parts"] == 1
    assert abs(st["Volume"] - solid.volume) < 5e-3 * solid.volume


def test_bad_tolerance_writes_nothing(tmp_path):
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.export_stl(_solid(), tmp_path / "x.stl", tolerance=0.0)
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.export_stl(sm.sphere(1.0), tmp_path / "x.stl", tolerance=1e-9)
    assert list(tmp_path.iterdir()) == []


def test_edge_use_agrees_with_trimesh(tmp_path):
    """``Mesh.edge_use`` (the command's watertight line without trimesh) says what trimesh
    says: a closed solid, an open patch, a solid with facets turned, one with a facet lost."""
    import build123d as bd

    mesh = sm.export_stl(bd.Cylinder(2, 3) - bd.Box(1, 1, 5), tmp_path / "part.stl", tolerance=0.01)
    open_patch = sm.tessellate(sm.sphere(1.0), 0.01)
    flipped = sm.Mesh(mesh.vertices, np.concatenate([mesh.faces[:7, ::-1], mesh.faces[7:]]))
    holed = sm.Mesh(mesh.vertices, mesh.faces[1:])
    answers = []
    for m in (mesh, open_patch, flipped, holed):
        tm = m.to_trimesh()
        assert m.edge_use() == (tm.is_watertight, tm.is_winding_consistent)
        answers.append(m.edge_use())
    assert answers[0] == (True, True) and answers[2] == (True, False) and answers[3][0] is False
