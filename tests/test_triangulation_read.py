"""Reading BRepMesh triangulations out of OCCT in one binary dump
(``surfmod.occ.mesh._triangulation_table``) gives, face for face, exactly what reading
node by node gives; located copies of one face share their entry; a dump that does not
follow the expected layout is refused (and ``mesh_faces`` then reads face by face).
Geometry read the same way: tests/test_occ_binary.py."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
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

