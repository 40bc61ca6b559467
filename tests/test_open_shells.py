"""Open shells from real parts (a corpus solid with its largest faces taken out, see
tests/open_shells.py): commands that need a closed solid (``mass``, ``femesh``) refuse
in one line naming the file, exit 1 and write nothing; ``mesh``, ``section`` and
``toolpath`` work on them and are judged as on closed parts (OCCT's distance for the
STL, ``BRepAlgoAPI_Section``'s length for the DXF, the exact swept-tool check for the
G-code).  One file in the default run, several under the ``corpus`` marker."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import CORPUS
from open_shells import open_shell_step
from test_corpus_mesh import _independent_deviation
from test_corpus_readback import dxf_length
from test_corpus_toolpath import run_and_judge

import surfmod as sm
from surfmod.cli import main
from surfmod.occ.sample import edge_length, wire_edges
from surfmod.occ.properties import bounding_box
from surfmod.occ.booleans import cut_edges, wires_of

QUICK = CORPUS / "cadquery_red_cube_blue_cylinder.step"
SWEEP = ["occt_screw.step", "trimesh_featuretype.STEP", "pythonocc_face_recognition_sample_part.stp",
         "build123d_M6-1x12-countersunk-screw.step", "occt_linkrods.step", "trimesh_box_sides.STEP"]


@pytest.fixture(scope="module")
def quick_shell(tmp_path_factory):
    return open_shell_step(QUICK, tmp_path_factory.mktemp("open"))


def _refused(command, path, out, capsys):
    capsys.readouterr()
    code = main([command, str(path), *out, "--no-progress"])
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert code == 1 and len(err.splitlines()) == 1, err
    assert path.name in err and "not closed" in err, err
    return captured.out


def check_needs_closed(path, tmp_path, capsys):
    """``mass`` and ``femesh`` refuse the open shell: one line naming the file, exit 1,
    no output file."""
    assert _refused("mass", path, [], capsys) == ""
    msh = tmp_path / "part.msh"
    _refused("femesh", path, ["--size", "1", "--out", str(msh)], capsys)
    assert not msh.exists()
    with pytest.raises(sm.SurfmodError, match="not closed"):
        sm.mass_properties(sm.import_step(path))


def _edge_uses(path):
    """How many facets use each edge of the STL (vertices merged)."""
    import trimesh

    tm = trimesh.load(str(path), file_type="stl", process=False)
    _, inverse = np.unique(tm.vertices, axis=0, return_inverse=True)
    f = inverse.reshape(-1)[tm.faces]
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    return np.unique(edges, axis=0, return_counts=True)[1]


def check_mesh(path, tmp_path, capsys):
    """The STL is written, measured within the tolerance by OCCT's distance, open exactly
    along the missing faces (edges used once), and says it is not watertight."""
    shape = sm.import_step(path)
    box = bounding_box(shape.wrapped)
    tol = 1e-3 * float(np.linalg.norm(box[1] - box[0]))
    out = tmp_path / "part.stl"
    capsys.readouterr()
    assert main(["mesh", str(path), "--tolerance", repr(tol), "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "watertight False" in printed and "lie in no closed shell" in printed, printed
    uses = _edge_uses(out)
    assert (uses == 1).any() and uses.max() == 2
    assert _independent_deviation(shape, out, tol) <= tol


def check_section(path, tmp_path, capsys):
    """DXF through the bounding-box centre: length equal to BRepAlgoAPI_Section's.  The
    first plane (z, tilted, x, y) that OCCT finds crossing the shell is used (the faces
    taken out may be all the z plane met)."""
    shell = sm.import_step(path).wrapped
    centre = bounding_box(shell).mean(axis=0)
    out = tmp_path / "part.dxf"
    tilted = np.array([0.1, 0.2, 1.0]) / math.sqrt(1.05)
    for normal in (np.array([0.0, 0.0, 1.0]), tilted, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        ref = sum(edge_length(e) for w in wires_of(cut_edges(shell, centre, normal)) for e in wire_edges(w))
        if ref == 0:
            continue
        capsys.readouterr()
        code = main(["section", str(path), "--origin", *(repr(float(x)) for x in centre), "--normal",
                     *(repr(float(x)) for x in normal), "--out", str(out), "--no-progress"])
        assert code == 0, capsys.readouterr().err
        break
    assert code == 0
    assert abs(dxf_length(out) - ref) <= 1e-6 * ref


def check_all(source, tmp_path, capsys, drop):
    path = open_shell_step(source, tmp_path, drop)
    check_needs_closed(path, tmp_path, capsys)
    check_mesh(path, tmp_path, capsys)
    check_section(path, tmp_path, capsys)
    run_and_judge(path, tmp_path, capsys)


def test_open_shell_needs_closed_commands_refuse(quick_shell, tmp_path, capsys):
    check_needs_closed(quick_shell, tmp_path, capsys)


def test_open_shell_mesh(quick_shell, tmp_path, capsys):
    check_mesh(quick_shell, tmp_path, capsys)


def test_open_shell_section(quick_shell, tmp_path, capsys):
    check_section(quick_shell, tmp_path, capsys)


def test_open_shell_toolpath_never_gouges(quick_shell, tmp_path, capsys):
    run_and_judge(quick_shell, tmp_path, capsys)


@pytest.mark.corpus
@pytest.mark.parametrize("name", SWEEP)
def test_open_shells_of_corpus_parts(name, tmp_path, capsys):
    check_all(CORPUS / name, tmp_path, capsys, drop=2)


def _box_and_loose_face(tmp_path):
    """A STEP file holding a closed box and, beside it, one loose square (face 6)."""
    import build123d as bd

    path = tmp_path / "box_and_face.step"
    sm.export_step(bd.Compound([bd.Box(2, 3, 4), bd.Pos(5, 0, 0) * bd.Face.make_rect(1, 1)]), path)
    return path


def test_mass_names_the_faces_it_leaves_out(tmp_path, capsys):
    """Faces outside every closed solid enclose no volume: ``mass`` weighs the solid alone
    and says which faces it left out, where it used to drop them without a word (an Alias
    file, trj3_s1-al-214, has 50 such faces in 9 open shells beside its 5 solids)."""
    path = _box_and_loose_face(tmp_path)
    assert main(["mass", str(path), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "NOTE: 1 face(s) outside every closed solid (open shells or loose faces) are left out" in out
    assert "are left out, they enclose no volume: faces 6\n" in out and "AGREE" in out
    assert sm.mass_properties(path).volume == pytest.approx(24.0, rel=1e-14)


def test_mesh_leaves_out_faces_of_open_shells_brepmesh_cannot_triangulate(tmp_path, monkeypatch, capsys):
    """A face BRepMesh leaves without triangles: in an open shell (the STL is open there
    anyway) it is left out and named, unless ``--strict``; in a closed shell the STL would
    open, so it is refused.  BRepMesh's failure is simulated: the Alias file where it
    happens (8 sliver faces of open shells) is not in the corpus."""
    import surfmod.occ.mesh as occ_mesh

    path = _box_and_loose_face(tmp_path)
    real = occ_mesh.mesh_faces
    lost = {6}

    def losing(*a, **kw):
        return [(k, f, None if k in lost else t) for k, f, t in real(*a, **kw)]

    monkeypatch.setattr(occ_mesh, "mesh_faces", losing)
    out = tmp_path / "part.stl"
    assert main(["mesh", str(path), "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "NOTE: 1 face(s) of open shells BRepMesh cannot triangulate are left out: faces 6" in printed
    assert "watertight True" in printed and "lie in no closed shell" not in printed
    assert len(_edge_uses(out)) == 18 and _edge_uses(out).max() == 2  # the box alone, closed
    out.unlink()
    assert main(["mesh", str(path), "--out", str(out), "--strict", "--no-progress"]) == 1
    assert "of open shells" in capsys.readouterr().err and not out.exists()
    lost.clear()
    lost.add(0)
    assert main(["mesh", str(path), "--out", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "could not triangulate face 0" in err and "open shells" not in err and not out.exists()


# -- per-face commands: a face OCCT cannot triangulate or intersect is named, the rest done -------
def loose_bspline_faces(tmp_path):
    """A surface model of six loose bicubic B-spline faces (a 3 x 2 patchwork, not sewn):
    the kind of model of the issue whose face OCCT could not triangulate."""
    faces = []
    for i in range(3):
        for j in range(2):
            x, y = np.meshgrid(np.linspace(10 * i, 10 * i + 10, 5), np.linspace(10 * j, 10 * j + 10, 5), indexing="ij")
            net = np.stack([x, y, 2 * np.sin(x / 7) * np.cos(y / 5)], -1)
            faces.append(sm.BSplineSurface(net, degree=(3, 3)).face())
    path = tmp_path / "loose.step"
    sm.export_step(faces, path)
    return path


def _is_last_patch(face) -> bool:
    """The face over x in [20, 30], y in [10, 20] (the one made to fail)."""
    lo = bounding_box(face)[0]
    return lo[0] > 19 and lo[1] > 9


def test_analyze_skips_a_face_brepmesh_cannot_triangulate(tmp_path, monkeypatch, capsys):
    """BRepMesh's failure on one face is simulated (the public parts where it happens are
    not in the corpus): the picture of the other five is written, the face named, exit 3."""
    import surfmod.occ.mesh as occ_mesh

    path, out = loose_bspline_faces(tmp_path), tmp_path / "z.png"
    assert main(["analyze", str(path), "--out", str(out), "--resolution", "20"]) == 0
    assert "6 patch(es)" in capsys.readouterr().out
    out.unlink()
    real = occ_mesh.face_uv_triangles

    def failing(face, *a, **kw):
        if _is_last_patch(face):
            raise sm.SurfmodError("obj: OCCT could not triangulate a trimmed face's parameter region")
        return real(face, *a, **kw)

    monkeypatch.setattr(occ_mesh, "face_uv_triangles", failing)
    assert main(["analyze", str(path), "--out", str(out), "--resolution", "20"]) == 3
    printed = capsys.readouterr().out
    assert "analysis zebra: 5 patch(es)" in printed
    assert "face 5 skipped: obj: OCCT could not triangulate" in printed
    assert "partial: 1 of 6 face(s) skipped" in printed
    assert out.read_bytes()[:4] == b"\x89PNG"
    # nothing drawable: the error, exit 1, no file
    out.unlink()
    def never(*a, **kw):
        raise sm.SurfmodError("obj: no")

    monkeypatch.setattr(occ_mesh, "face_uv_triangles", never)
    assert main(["analyze", str(path), "--out", str(out), "--resolution", "20"]) == 1
    assert capsys.readouterr().err.startswith("surfmod analyze: error:") and not out.exists()


def test_section_goes_on_past_a_face_occt_cannot_intersect(tmp_path, monkeypatch, capsys):
    """BRepAlgoAPI_Section's failure on the whole model and on one face is simulated: the
    plane x = 25 crosses faces 4 and 5; face 5 is named, the DXF holds face 4's curve
    (its length BRepAlgoAPI_Section's of that face alone), exit 3."""
    import surfmod.occ.booleans as occ_section
    from OCP.TopAbs import TopAbs_FACE

    path, out = loose_bspline_faces(tmp_path), tmp_path / "s.dxf"
    faces = sm.import_step(path).faces()
    origin, normal = np.array([25.0, 0, 0]), np.array([1.0, 0, 0])
    per_face = [sum(edge_length(e) for w in wires_of(cut_edges(f.wrapped, origin, normal)) for e in wire_edges(w))
                for f in faces]
    assert [x > 0 for x in per_face] == [False] * 4 + [True] * 2
    real = occ_section.cut_edges

    def failing(shape, origin, normal):
        if shape.ShapeType() != TopAbs_FACE or _is_last_patch(shape):
            raise sm.SurfmodError("obj: OCCT could not section this shape")
        return real(shape, origin, normal)

    monkeypatch.setattr(occ_section, "cut_edges", failing)
    with pytest.raises(sm.SurfmodError, match="could not section"):
        sm.section(path, origin, normal)
    assert main(["section", str(path), "--origin", "25", "0", "0", "--normal", "1", "0", "0", "--out", str(out),
                 "--no-progress"]) == 3
    printed = capsys.readouterr().out
    assert "face 5 skipped: obj: OCCT could not section this shape" in printed
    assert "partial: 1 of 6 face(s) skipped" in printed
    assert "1 face(s) OCCT could not intersect left out: [5]" in printed
    assert dxf_length(out) == pytest.approx(per_face[4], rel=1e-9)
    # the plane crosses only the face OCCT cannot intersect: nothing to write
    out.unlink()
    assert main(["section", str(path), "--origin", "24", "24", "0", "--normal", "1", "1", "0", "--out", str(out),
                 "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("surfmod section: error: obj: the plane crosses no face but [5]") and err.count("\n") == 1
    assert not out.exists()


def test_check_names_a_face_it_cannot_check_and_exits_3(tmp_path, monkeypatch, capsys):
    """A face whose read-back fails (simulated) is a row "skip" naming the reason, the
    other five are checked and pass: exit 3 with the count.  A face failing its
    cross-check still makes exit 1."""
    import surfmod.cli.check as cli_check

    path = loose_bspline_faces(tmp_path)
    real = cli_check.from_face

    def failing(face):
        if _is_last_patch(face):
            raise sm.SurfmodError("face: OCCT could not evaluate this face")
        return real(face)

    monkeypatch.setattr(cli_check, "from_face", failing)
    assert main(["check", str(path), "--no-progress"]) == 3
    printed = capsys.readouterr().out
    rows = [line.split() for line in printed.splitlines() if line.startswith("loose.step")]
    assert [r[4] for r in rows] == ["yes"] * 5 + ["skip"] and "not checked: face: OCCT could not evaluate" in printed
    assert "5 of 6 faces passed" in printed
    assert "partial: 1 of 6 face(s) could not be checked: loose.step face 5" in printed
    csv_path = tmp_path / "rows.csv"
    assert main(["check", str(path), "--csv", str(csv_path), "--no-progress"]) == 3
    assert csv_path.read_text().count(",skip,") == 1

    monkeypatch.setattr(cli_check, "from_face", real)
    real_many = cli_check.crosscheck_many

    def one_fails(surfaces, **kw):  # the last face's cross-check fails by 1e-3
        results = real_many(surfaces, **kw)
        r = results[-1]
        results[-1] = type(r)(1e-3, r.mode, r.samples, False)
        results[-1].details = {"tolerance": 1e-9}
        return results

    monkeypatch.setattr(cli_check, "crosscheck_many", one_fails)
    assert main(["check", str(path), "--no-progress"]) == 1
    assert "5 of 6 faces passed" in capsys.readouterr().out
