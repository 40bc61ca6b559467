"""An STL is judged by reading it back before anything exits 0 (``surfmod.meshing.closure``):
every solid's triangles closed, 2-manifold, consistently outward, no degenerate facet,
checked against admesh (a real STL client); inside-out solids are said and meshed
outward."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from conftest import CORPUS
from stlcheck import ADMESH_REPAIRS, admesh_stats, needs_admesh

import surfmod as sm
from surfmod.cli import main
from surfmod.io.stl import write_binary
from surfmod.meshing.closure import closure, read_stl
from surfmod.occ.topo import faces_of
from test_step_roundtrip import _open_shell_solid


def _box_facets():
    """The 1 x 2 x 3 box as 12 outward facets, and the face (0..5) of each."""
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]  # outward
    tri = [(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads]
    return v[np.array(tri)], np.array(list(range(6)) * 2)


def _damaged():
    box, faces = _box_facets()
    flipped = box.copy()
    flipped[0] = flipped[0, ::-1]
    degenerate = box.copy()
    degenerate[0, 2] = degenerate[0, 1]
    return {
        "sound": (box, True),
        "open": (box[1:], False),
        "one facet flipped": (flipped, False),
        "inside out": (box[:, ::-1], False),
        "degenerate facet": (degenerate, False),
    }


@needs_admesh
@pytest.mark.parametrize("case", sorted(_damaged()))
def test_closure_agrees_with_admesh(tmp_path, case):
    corners, sound = _damaged()[case]
    verdict = closure(corners)
    assert verdict.sound == sound, verdict.describe()
    path = tmp_path / "t.stl"
    with open(path, "wb") as fh:
        write_binary(fh, corners)
    np.testing.assert_array_equal(read_stl(path), corners.astype(np.float32))
    stats = admesh_stats(path)
    admesh_sound = all(stats[k] == 0 for k in ADMESH_REPAIRS) and stats["Volume"] > 0
    assert admesh_sound == sound, stats


def test_closure_names_the_faces_along_bad_edges():
    box, faces = _box_facets()
    c = closure(box[1:], faces[1:])  # facet 0 (of face 0) missing: its three edges are open
    assert (c.open, c.inconsistent, c.non_manifold, c.degenerate) == (3, 0, 0, 0)
    assert c.faces == (0, 2, 5) and not c.sound  # its edges: the diagonal, x=y=0 (face 2), top (face 5)


@needs_admesh
def test_export_stl_meshes_an_inside_out_solid_outward_and_says_so(tmp_path):
    import build123d as bd

    box = bd.Solid(bd.Solid.make_box(1, 2, 3).wrapped.Reversed())
    with pytest.warns(sm.InsideOutWarning, match=r"^solid 1 is inside out \(enclosed volume -6\): meshed outward$"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", sm.RoundTripWarning)
            mesh = sm.export_stl(box, tmp_path / "box.stl", 0.01)
    assert mesh.info["inside_out_solids"] == [(1, pytest.approx(-6.0, rel=1e-12))] and not mesh.info["stl_problems"]
    stats = admesh_stats(tmp_path / "box.stl")
    assert all(stats[k] == 0 for k in ADMESH_REPAIRS) and stats["Volume"] == pytest.approx(6.0, rel=1e-6)


def _one_face_flipped():
    """A box whose third face is reversed in its (closed) shell: inconsistently oriented."""
    import build123d as bd
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Shell, TopoDS_Solid

    builder, shell, solid = BRep_Builder(), TopoDS_Shell(), TopoDS_Solid()
    builder.MakeShell(shell)
    for i, face in enumerate(faces_of(bd.Solid.make_box(1, 2, 3).wrapped)):
        builder.Add(shell, face.Reversed() if i == 2 else face)
    shell.Closed(True)
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    return solid


@needs_admesh
def test_export_stl_turns_the_faces_at_odds_with_their_neighbours(tmp_path):
    # a solid whose faces disagree: made consistent from the connectivity (face 2 turned
    # to agree with its four neighbours), outward from the enclosed volume
    with pytest.warns(sm.InsideOutWarning, match=r"^solid 1: face\(s\) 2 point against their neighbours"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", sm.RoundTripWarning)
            mesh = sm.export_stl(_one_face_flipped(), tmp_path / "f.stl", 0.01)
    assert mesh.info["faces_turned"] == [(1, [2])] and mesh.info["inside_out_solids"] == []
    stats = admesh_stats(tmp_path / "f.stl")
    assert all(stats[k] == 0 for k in ADMESH_REPAIRS) and stats["Volume"] == pytest.approx(6.0, rel=1e-6)


def test_strict_refuses_an_stl_that_breaks_its_promise(tmp_path, monkeypatch):
    _fake_mesher(monkeypatch, open_until=0.0)
    with pytest.raises(sm.SurfmodError, match=r"^objects: the STL read back breaks its promise .*3 open edge"):
        sm.export_stl("part", tmp_path / "g.stl", 0.01, strict=True)
    assert not list(tmp_path.iterdir())


def test_export_stl_of_an_open_shell_promises_no_closure(tmp_path):
    # faces in no closed shell are the model's openness (noted as open faces), not a broken promise
    with warnings.catch_warnings():
        warnings.simplefilter("error", sm.RoundTripWarning)
        mesh = sm.export_stl(_open_shell_solid(), tmp_path / "open.stl", 0.01)
    assert mesh.info["open_faces"] == 5 and mesh.info["stl_problems"] == []


def test_mesh_command_says_an_inside_out_file_solid_in_one_line(tmp_path, capsys):
    # stepcode_HEAD_BACK.stp's closed shell points inwards in the file (OCCT's reader turns it)
    out = tmp_path / "h.stl"
    assert main(["mesh", str(CORPUS / "stepcode_HEAD_BACK.stp"), "--out", str(out), "--tolerance", "0.5",
                 "--no-progress"]) == 0
    captured = capsys.readouterr()
    said = [line for line in captured.err.splitlines() if "inside out" in line]
    assert said == ["surfmod mesh: warning: stepcode_HEAD_BACK.stp: solid 1 is inside out in the file "
                    "(enclosed volume -880933): read outward"], captured.err
    assert "BROKEN" not in captured.out


def test_convert_to_stl_exits_3_naming_a_solid_left_open(tmp_path, capsys, monkeypatch):
    from surfmod.occ.step import write_brep

    brep = tmp_path / "f.brep"
    write_brep(_one_face_flipped(), brep)
    _fake_mesher(monkeypatch, open_until=0.0)
    assert main(["convert", str(brep), str(tmp_path / "f.stl"), "--tolerance", "0.01"]) == 3
    out = capsys.readouterr().out
    assert "BROKEN: solid 1: 3 open edge(s); along face(s) 0, 2, 5" in out and (tmp_path / "f.stl").exists()


def _fake_mesher(monkeypatch, open_until: float, flipped: bool = False):
    """``export_stl``'s mesher replaced: the box, open (a facet missing) at tolerances
    above ``open_until``, closed at or below it; inside out when ``flipped``.  Returns
    the tolerances asked for."""
    import surfmod.io.stl as stl

    asked = []

    def mesh_of(obj, tolerance, strict, progress):
        asked.append(tolerance)
        corners, faces = _box_facets()
        if flipped:
            corners = corners[:, ::-1]
        if tolerance > open_until:
            corners, faces = corners[1:], faces[1:]
        v = corners.reshape(-1, 3)
        info = {"stl_groups": [("solid 1", len(corners), faces)], "faces_over_tolerance": []}
        return sm.Mesh(v, np.arange(len(v)).reshape(-1, 3), info)

    monkeypatch.setattr(stl, "_mesh_of", mesh_of)
    return asked


@needs_admesh
def test_an_open_stl_is_meshed_again_finer_until_it_closes(tmp_path, monkeypatch):
    asked = _fake_mesher(monkeypatch, open_until=0.005)
    with warnings.catch_warnings():
        warnings.simplefilter("error", sm.RoundTripWarning)
        mesh = sm.export_stl("part", tmp_path / "box.stl", 0.01)
    assert asked == [0.01, 0.005] and mesh.info["stl_problems"] == []
    assert mesh.info["remeshed"] == ("solid 1: 3 open edge(s); along face(s) 0, 2, 5 at tolerance 0.01: closed "
                                     "meshed again at 0.005")
    stats = admesh_stats(tmp_path / "box.stl")
    assert stats["Number of facets"] == 12 and all(stats[k] == 0 for k in ADMESH_REPAIRS)


def test_an_stl_that_stays_open_is_said_and_the_first_mesh_kept(tmp_path, monkeypatch):
    asked = _fake_mesher(monkeypatch, open_until=0.0)
    with pytest.warns(sm.RoundTripWarning, match=r"^box.stl read back breaks its promise: solid 1: 3 open edge"):
        mesh = sm.export_stl("part", tmp_path / "box.stl", 0.01)
    assert asked == [0.01, 0.005, 0.0025, 0.00125] and len(read_stl(tmp_path / "box.stl")) == len(mesh.faces) == 11


def test_an_stl_is_meshed_again_down_to_an_eighth_of_the_tolerance(tmp_path, monkeypatch):
    # a propeller's blade tip (bitcraze-mechanics' FreeCAD mockup): two B-spline faces meet
    # at a knife edge and share triangles along it (5, 3 and 4 non-manifold edges at 0.01,
    # 0.005 and 0.0025); at 0.00125 the mesh parts them and the STL closes
    asked = _fake_mesher(monkeypatch, open_until=0.00125)
    with warnings.catch_warnings():
        warnings.simplefilter("error", sm.RoundTripWarning)
        mesh = sm.export_stl("part", tmp_path / "box.stl", 0.01)
    assert asked == [0.01, 0.005, 0.0025, 0.00125] and mesh.info["stl_problems"] == []
    assert mesh.info["remeshed"].endswith("at tolerance 0.01: closed meshed again at 0.00125")


def test_orientation_is_not_meshed_again(tmp_path, monkeypatch):
    asked = _fake_mesher(monkeypatch, open_until=1.0, flipped=True)
    with pytest.warns(sm.RoundTripWarning, match=r"solid 1: enclosed volume -6 \(inside out or not closed\)$"):
        sm.export_stl("part", tmp_path / "box.stl", 0.01)
    assert asked == [0.01]


def test_faces_are_turned_only_where_whole_faces_can_agree():
    from surfmod.meshing.closure import faces_against_neighbours

    tet = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    odd = np.vstack([tet[:3], tet[3, ::-1]])
    assert faces_against_neighbours(odd, np.arange(4)) == [3]
    assert faces_against_neighbours(odd, np.array([0, 1, 2, 2])) == []  # face 2 at odds with itself
    assert faces_against_neighbours(odd[:, ::-1], np.arange(4)) == [3]  # the fewer triangles turn
    two = np.vstack([odd, tet + 4])  # two tetrahedra (one solid of two shells): each set by itself
    assert faces_against_neighbours(two, np.array([0, 1, 2, 3, 4, 5, 6, 7])) == [3]
