"""`surfmod mesh` / `export_stl` on real STEP parts (tests/data/step): the STL is
watertight and needs no admesh repair on every solid, its deviation is measured against
the exact faces (checked here by OCCT's own distance), and faces the model itself
holds off the surface are reported, or refused with ``--strict``.

The whole-corpus sweep is marked ``corpus``; occt_screw.step (the file whose spindle
torus faces used to be "measured" 3.09 off) runs in the default suite.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import CORPUS
from stlcheck import ADMESH_REPAIRS, admesh_stats, needs_admesh
from toolpath_reference import compound, face_boxes

import surfmod as sm
from surfmod.cli import main
from surfmod.meshing.brep import DENSE, measure_face
from surfmod.meshing.figures import shape_diagonal
from surfmod.meshing.facemesh import brepmesh
from surfmod.occ.bindings import OCCT_VERSION
from surfmod.occ.sample import distances_to_face
from surfmod.occ.topo import faces_of, solids_of

SCREW = CORPUS / "occt_screw.step"

#: files whose model itself breaks the STL's promise: the mesh cannot be closed and
#: 2-manifold there, so the command exits 3 naming the solid and faces (never 0).
#: file -> (solid, B-rep faces named, the judge's words as a pattern, the model's defect).
#: The defect is the model's, shown apart from any mesh: BRepAlgoAPI_Check finds that
#: solid, and only it, invalid (test_model_defects_are_the_models).
MODEL_DEFECTS = {
    "zoo_car-wheel-assembly.step": (
        42, (289, 305), r"solid 42: \d+ non-manifold edge\(s\); along face\(s\) 289, 305",
        "solid 42 (a quarter of the rim) covers a band of its cylinder r 153.67 twice: face 305 "
        "(z -14.478 .. -12.7) lies on face 289 (z -36.322 .. -12.7), turned the other way, the two "
        "sharing three edges (a sheet of no thickness); BRepCheck passes it, BRepAlgoAPI_Check "
        "(self-interference) does not"),
}


def _mesh_and_check(step, tmp_path, relative=1e-3, strict=False, code=0):
    """Run ``surfmod mesh`` at ``relative`` x the bbox diagonal, which must exit ``code``;
    return ``(shape, tolerance, STL path)``."""
    shape = sm.import_step(step)
    diag = shape_diagonal(shape)
    tol = relative * diag
    out = tmp_path / "part.stl"
    args = ["mesh", str(step), "--tolerance", repr(tol), "--out", str(out), "--no-progress"]
    assert main(args + (["--strict"] if strict else [])) == code
    return shape, tol, out


def _independent_deviation(shape, path, tol, count=120):
    """OCCT's distance (BRepExtrema) from sample points of the written STL's triangles
    (the worst-looking ones: farthest from their own plane's fit is unknown, so spread
    evenly) to the shape.  Each point is measured against the faces whose bounding boxes
    come within ``2 tol`` of it: the closest face of a point within ``tol`` is among them,
    and a point with none is more than ``tol`` away (inf).  The same verdict as against
    the whole shape, whose 1018 faces took BRepExtrema a second a point on 11752."""
    import trimesh

    tm = trimesh.load(str(path), file_type="stl", process=False)
    tri = tm.vertices[tm.faces]
    pick = tri[:: max(1, len(tri) // count)]
    pts = np.einsum("kj,tjd->tkd", DENSE[[0, 12, 24]], pick).reshape(-1, 3)
    faces, boxes = face_boxes(getattr(shape, "wrapped", shape))
    worst = 0.0
    for p in pts:
        near = np.nonzero(np.all((boxes[:, 0] - 2 * tol <= p) & (p <= boxes[:, 1] + 2 * tol), axis=1))[0]
        if not len(near):
            return np.inf
        worst = max(worst, float(distances_to_face(compound(faces[k] for k in near), p[None])[0]))
    return worst


def closed_and_oriented(path) -> bool:
    """Every solid in the STL is closed and consistently oriented: after merging equal
    (float32) vertices, each directed edge is matched by as many opposite ones.  Unlike
    a single-body watertightness test this holds for an assembly whose solids touch
    (their shared edges carry four facets)."""
    import trimesh

    tm = trimesh.load(str(path), file_type="stl", process=False)
    _, inverse = np.unique(tm.vertices, axis=0, return_inverse=True)
    f = inverse.reshape(-1)[tm.faces]
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    fwd, n_fwd = np.unique(directed, axis=0, return_counts=True)
    back, n_back = np.unique(directed[:, ::-1], axis=0, return_counts=True)
    return bool(np.array_equal(fwd, back) and np.array_equal(n_fwd, n_back))


def _check_stl(shape, path, tol):
    n_solids = len(solids_of(getattr(shape, "wrapped", shape)))
    closed = n_solids > 0 and all(f.solid >= 0 for f in brepmesh(shape, 10 * tol))
    if closed:  # open shells: the STL is written, it need not be watertight
        assert closed_and_oriented(path)
    st = admesh_stats(path)
    # loose faces (pythonocc_splinecage.stp) have free edges, which admesh "repairs" by
    # filling the holes; their triangles must still be proper and consistently wound
    for key in ADMESH_REPAIRS if closed else ("Degenerate facets", "Backwards edges"):
        assert st[key] == 0, (key, st)
    return st


@needs_admesh
@pytest.mark.parametrize("relative", [1e-3, 2e-4])
def test_screw_meshes_watertight_within_tolerance_strict(tmp_path, relative):
    shape, tol, out = _mesh_and_check(SCREW, tmp_path, relative, strict=True)
    _check_stl(shape, out, tol)
    assert _independent_deviation(shape, out, tol) <= tol


def test_spindle_torus_faces_are_measured_like_occt():
    """occt_screw.step's tori have minor radius > major radius: the tube crosses the
    axis, and the closed-form distance must take the mirrored profile circle too."""
    shape = sm.import_step(SCREW)
    fms = [fm for fm in brepmesh(shape, 0.05) if "Toroidal" in fm.surface.DynamicType().Name()]
    assert len(fms) == 3
    for fm in fms:
        assert fm.surface.MinorRadius() > fm.surface.MajorRadius()
        per_triangle, nodes = measure_face(fm, 0.0)
        worst = np.argsort(per_triangle)[-5:]
        pts = np.einsum("kj,tjd->tkd", DENSE, fm.nodes[fm.triangles[worst]])
        occt = distances_to_face(fm.face, pts.reshape(-1, 3)).reshape(len(worst), -1).max(axis=1)
        assert np.allclose(occt, per_triangle[worst], rtol=1e-6, atol=1e-12)
        assert per_triangle.max() < 0.05 and nodes < 1e-3


def test_strict_refuses_and_writes_nothing(tmp_path, monkeypatch, capsys):
    """A near-tangent boolean whose edges carry 0.056 tolerance (the STEP round trip
    would tighten them, so the solid goes to the command as the reader's result)."""
    import build123d as bd

    import surfmod.cli.mesh_stl as cli_mesh

    solid = bd.fillet(bd.Solid.make_box(10, 10, 10).edges(), 2) - bd.Solid.make_cylinder(2, 10)
    monkeypatch.setattr(cli_mesh, "read_step_file", lambda path, name: solid.wrapped)
    out = tmp_path / "t.stl"
    assert main(["mesh", "part.step", "--tolerance", "0.01", "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    n = 2 if OCCT_VERSION >= (8, 0) else 1  # OCCT 8.0's boolean leaves two such corners
    assert "watertight True" in text and f"{n} face(s) deviate more than 0.01" in text
    assert "(SphericalSurface): measured 0.0251" in text and "model tolerance 0.056" in text
    out.unlink()
    assert main(["mesh", "part.step", "--tolerance", "0.01", "--out", str(out), "--strict", "--no-progress"]) != 0
    assert f"not met on {n} face" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.corpus
@needs_admesh
def test_every_corpus_part_meshes_watertight_with_no_admesh_repair(corpus_file, tmp_path, capsys):
    if corpus_file.name in MODEL_DEFECTS:  # exit 3 naming the model's broken solid, and only it
        _, _, said, _ = MODEL_DEFECTS[corpus_file.name]
        shape, tol, out = _mesh_and_check(corpus_file, tmp_path, code=3)
        broken = [line for line in capsys.readouterr().out.splitlines() if line.startswith("BROKEN:")]
        assert len(broken) == 1 and re.fullmatch("BROKEN: " + said, broken[0]), broken
        assert _independent_deviation(shape, out, tol) <= tol
        return
    shape, tol, out = _mesh_and_check(corpus_file, tmp_path)
    st = _check_stl(shape, out, tol)
    assert st["Number of facets"] > 0
    assert _independent_deviation(shape, out, tol) <= tol


@pytest.mark.corpus
@pytest.mark.parametrize("name", sorted(MODEL_DEFECTS))
def test_model_defects_are_the_models(name):
    """The solid each pin blames is the one OCCT's own boolean checker finds invalid
    (self-interference), and no other solid of the file is: the defect is the model's,
    seen without meshing it."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Check

    solid, faces, _, _ = MODEL_DEFECTS[name]
    shape = sm.import_step(CORPUS / name)
    solids = solids_of(shape.wrapped)
    assert [i + 1 for i, s in enumerate(solids) if not BRepAlgoAPI_Check(s).IsValid()] == [solid]
    named = [f for k, f in enumerate(faces_of(shape)) if k in faces]
    assert len(named) == len(faces) and all(any(f.IsSame(g) for g in faces_of(solids[solid - 1])) for f in named)
