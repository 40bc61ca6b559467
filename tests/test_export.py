"""STEP and STL export: atomic writes, real files read back by OCCT / trimesh."""

from __future__ import annotations

import os

import numpy as np
import pytest

import surfmod as sm


@pytest.fixture
def surface(rng):
    return sm.BSplineSurface(rng.uniform(-1, 1, (5, 4, 3)), (3, 2), weights=rng.uniform(0.5, 2, (5, 4)))


def test_step_round_trip_is_exact(tmp_path, surface):
    path = tmp_path / "s.step"
    sm.export_step(surface, path)
    shape = sm.import_step(path)
    faces = shape.faces()
    assert len(faces) == 1
    back = sm.from_face(faces[0])
    us = np.linspace(0, 1, 7)
    np.testing.assert_allclose(back.grid(us, us), surface.grid(us, us), atol=1e-12)
    assert sm.crosscheck(faces[0]).passed


def test_step_of_several_objects_and_build123d_shapes(tmp_path, surface):
    import build123d as bd

    path = tmp_path / "many.step"
    sm.export_step([surface, sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), bd.Box(1, 2, 3)], path)
    assert len(sm.import_step(path).faces()) == 1 + 1 + 6


def test_failed_export_leaves_no_partial_file_and_keeps_the_old_one(tmp_path, surface):
    path = tmp_path / "keep.step"
    path.write_text("old content")
    with pytest.raises(sm.SurfmodError, match="objects"):
        sm.export_step([surface, object()], path)
    assert path.read_text() == "old content"
    assert sorted(os.listdir(tmp_path)) == ["keep.step"]


def test_exports_get_ordinary_file_modes(tmp_path, surface):
    # the atomic writer's temporary file is 0600; a new export must get 0666 minus the umask
    # and an overwritten file must keep its mode
    umask = os.umask(0o022)
    try:
        new = tmp_path / "new.stl"
        sm.export_stl(surface, new, tolerance=0.05)
        assert new.stat().st_mode & 0o777 == 0o644
        kept = tmp_path / "kept.step"
        kept.write_text("old")
        kept.chmod(0o640)
        sm.export_step(surface, kept)
        assert kept.stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(umask)


def test_export_path_errors(tmp_path, surface):
    with pytest.raises(sm.SurfmodError, match="path: folder .* does not exist"):
        sm.export_step(surface, tmp_path / "missing" / "a.step")
    with pytest.raises(sm.SurfmodError, match="path: expected a file ending in .step"):
        sm.export_step(surface, tmp_path / "a.txt")
    with pytest.raises(sm.SurfmodError, match="path: .* is a directory"):
        sm.export_stl(surface, tmp_path)
    with pytest.raises(sm.SurfmodError, match="tolerance: must be a finite number > 0"):
        sm.export_stl(surface, tmp_path / "a.stl", tolerance=0)


def test_unreadable_step_files(tmp_path):
    bad = tmp_path / "bad.step"
    bad.write_text("this is not STEP")
    with pytest.raises(sm.SurfmodError, match="path: .* is not a STEP file"):
        sm.import_step(bad)
    with pytest.raises(sm.SurfmodError, match="path: no such file"):
        sm.import_step(tmp_path / "nothing.step")
    broken = tmp_path / "broken.step"
    broken.write_text("ISO-10303-21;\nHEADER;\nGARBAGE((;\n")
    with pytest.raises(sm.SurfmodError, match="path"):
        sm.import_step(broken)


def test_stl_binary_and_ascii_read_back(tmp_path, surface):
    import trimesh

    for ascii_ in (False, True):
        path = tmp_path / f"s{int(ascii_)}.stl"
        written = sm.export_stl(surface, path, ascii=ascii_)
        back = trimesh.load(path, force="mesh")
        assert len(back.faces) == len(written.faces)
        np.testing.assert_allclose(back.area, written.area, rtol=1e-5)


def test_stl_of_a_closed_solid_is_watertight(tmp_path):
    import build123d as bd
    import trimesh

    part = bd.Box(10, 10, 10) - bd.Cylinder(3, 20)
    path = tmp_path / "part.stl"
    sm.export_stl(part, path, tolerance=0.01)
    back = trimesh.load(path)
    assert back.is_watertight and back.is_winding_consistent
    assert abs(back.volume - part.volume) < 0.01 * part.volume


def test_grid_mesh_is_the_lectures_m_by_n(surface):
    msh = sm.mesh(surface, 4, 3)
    us, vs = np.linspace(0, 1, 4), np.linspace(0, 1, 3)
    np.testing.assert_allclose(msh.vertices.reshape(4, 3, 3), surface.grid(us, vs))
    assert msh.faces.shape == (2 * 3 * 2, 3)
    quads = sm.mesh(surface, 4, 3, quads=True)
    assert quads.faces.shape == (3 * 2, 4)


def test_grid_mesh_triangles_face_along_the_normal():
    x, y = np.meshgrid(np.linspace(0, 3, 4), np.linspace(0, 2, 3), indexing="ij")
    bump = sm.BezierSurface(np.stack([x, y, 0.3 * np.sin(x + y)], axis=-1))
    msh = sm.mesh(bump, 20, 15)
    uv = np.stack(np.meshgrid(np.linspace(0, 1, 20), np.linspace(0, 1, 15), indexing="ij"), axis=-1).reshape(-1, 2)
    centroid = uv[msh.faces].mean(axis=1)
    tri = msh.vertices[msh.faces]
    n_tri = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n_tri /= np.linalg.norm(n_tri, axis=1, keepdims=True)
    assert np.all(np.einsum("ij,ij->i", n_tri, bump.normals(centroid[:, 0], centroid[:, 1])) > 0.99)
