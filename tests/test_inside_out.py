"""Inside-out solids met head-on: a solid whose faces point into its material is found
from the model (the sign of its enclosed volume, the shell as the file has it), turned
outward as a whole, and every command that reads solids says so in one line naming it."""

from __future__ import annotations

import warnings

import pytest
from conftest import CORPUS

import surfmod as sm
from surfmod.cli import main


@pytest.fixture(scope="module")
def inside_out_step(tmp_path_factory):
    """A STEP file of a 10 x 20 x 30 box turned inside out (``TopoDS_Shape.Reversed()``)."""
    import build123d as bd

    path = tmp_path_factory.mktemp("inside_out") / "rev.step"
    with pytest.warns(sm.RoundTripWarning, match=r"solid 1: enclosed volume -6000 -> 6000 \(turned outward\)"):
        sm.export_step(bd.Solid.make_box(10, 20, 30).wrapped.Reversed(), path)
    return path


LINE = "warning: rev.step: solid 1 is inside out in the file (enclosed volume -6000): read outward"


def test_import_step_names_the_solid_and_reads_it_outward(inside_out_step):
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    with pytest.warns(sm.InsideOutWarning) as said:
        part = sm.import_step(inside_out_step)
    assert [str(w.message) for w in said] == [LINE.removeprefix("warning: ")]
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(part.wrapped, props)
    assert props.Mass() == pytest.approx(6000.0, rel=1e-12)


def test_a_corpus_solid_inside_out_in_its_file_is_named_and_its_rewrite_is_not():
    # stepcode_HEAD_BACK.stp: OCCT's reader turns its closed shell (REVERSED); written
    # outward and read again it is not inside out, though the reader turns it again
    with pytest.warns(sm.InsideOutWarning, match=r"^stepcode_HEAD_BACK.stp: solid 1 is inside out in the file "
                                                 r"\(enclosed volume -880933\): read outward$"):
        part = sm.import_step(CORPUS / "stepcode_HEAD_BACK.stp")
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("error", sm.InsideOutWarning)
        sm.export_step(part, Path(tmp) / "again.step")
        sm.import_step(Path(tmp) / "again.step")


@pytest.mark.parametrize("args", [
    ["mass"],
    ["check", "--samples", "8"],
    ["mesh", "--tolerance", "0.5", "--out", "{tmp}/rev.stl"],
    ["toolpath", "--radius", "2", "--scallop", "0.5", "--out", "{tmp}/rev.nc"],
    # the whole job, verified against the part read outward (issue 36): exit 0 means its
    # gouge, rapid and residual checks held, which they cannot on material turned inside out
    ["machine", "--rough", "flat:5", "--finish", "ball:5", "--scallop", "0.5", "--stock-margin", "1",
     "--out", "{tmp}/rev.ngc"],
], ids=lambda a: a[0])
def test_every_command_that_reads_solids_says_so_in_one_line(inside_out_step, tmp_path, capsys, args):
    command, *rest = args
    code = main([command, str(inside_out_step), *(a.format(tmp=tmp_path) for a in rest), "--no-progress"])
    assert code == 0
    err = capsys.readouterr().err.splitlines()
    assert [line for line in err if "inside out" in line] == [f"surfmod {command}: {LINE}"]


def test_faces_at_odds_are_found_from_the_model():
    import build123d as bd
    from test_stl_verify import _one_face_flipped

    from surfmod.occ.solids import faces_at_odds

    # face 2 reversed in the shell: its four edges run the same way as in its neighbours
    assert faces_at_odds(_one_face_flipped()) == [(1, 4, [0, 1, 2, 4, 5])]
    assert faces_at_odds(bd.Solid.make_box(1, 2, 3).wrapped.Reversed()) == []  # inside out, but consistent
    assert faces_at_odds(sm.import_step(CORPUS / "occt_linkrods.step").wrapped) == []


@pytest.mark.parametrize("case", ["inside out", "one face at odds"])
def test_mass_orients_a_solid_from_the_model_and_says_so(case):
    import build123d as bd
    from test_stl_verify import _one_face_flipped

    solid = bd.Solid.make_box(1, 2, 3).wrapped.Reversed() if case == "inside out" else _one_face_flipped()
    said = r"solid 1 is inside out \(enclosed volume -6\): turned outward" if case == "inside out" else \
        r"solid 1: face\(s\) 2 of its shell point against their neighbours: turned to agree with them"
    with pytest.warns(sm.InsideOutWarning, match=said):
        r = sm.mass_properties(solid)
    assert r.volume == pytest.approx(6.0, rel=1e-12)  # the 1 x 2 x 3 box, not 4 or -6
    assert r.centroid == pytest.approx([0.5, 1.0, 1.5], abs=1e-12)


@pytest.mark.parametrize("method", ["numpy", "occt"])
def test_mass_turns_each_solid_of_a_compound_by_its_own_measured_volume(method):
    """The volume that orients a solid is the one measured (no BRepGProp pass first): in
    a compound of a box and a box inside out beside it only the second is turned, named,
    and both count outward."""
    import build123d as bd

    from surfmod.occ.topo import compound

    first = bd.Solid.make_box(1, 2, 3).wrapped
    second = bd.Solid.make_box(1, 2, 3).moved(bd.Location((10, 0, 0))).wrapped.Reversed()
    with pytest.warns(sm.InsideOutWarning) as said:
        r = sm.mass_properties(compound([first, second]), method=method)
    assert [str(w.message) for w in said] == ["solid 2 is inside out (enclosed volume -6): turned outward"]
    assert r.volume == pytest.approx(12.0, rel=1e-12)
    assert r.centroid == pytest.approx([5.5, 1.0, 1.5], abs=1e-12)
    alone = sm.mass_properties(first, method=method)  # about its own centroid; the pair's adds 2 x 6 x 5^2 in y, z
    assert r.inertia.diagonal() == pytest.approx(2 * alone.inertia.diagonal() + [0, 300, 300], rel=1e-12)
