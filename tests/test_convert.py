"""``surfmod convert IN OUT [--check]``: exit 0 only when the file written reads back as
what was read (faces, solids, each solid's volume and centroid to 1e-12), 3 when written
but changed (named), 1 on bad input with nothing written."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import CORPUS
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps

import surfmod as sm
from surfmod.cli import main
from surfmod.occ.step import write_brep
from surfmod.occ.topo import solids_of
from test_step_roundtrip import _open_shell_solid

PART = CORPUS / "nist_ctc_01_asme1_rd.stp"  # round trips bit-exact (tests/test_step_roundtrip.py)


def _volume(shape):
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def test_convert_step_to_step_and_brep_reports_equal_solids(tmp_path, capsys):
    want = _volume(solids_of(sm.import_step(PART).wrapped)[0])
    for out in (tmp_path / "a.step", tmp_path / "a.brep"):
        assert main(["convert", str(PART), str(out), "--check"]) == 0
        text = capsys.readouterr().out
        assert "faces 139 -> 139, solids 1 -> 1" in text and "reads back as written" in text
        volumes = [float(v) for v in re.search(r"solid 1: volume (\S+) -> (\S+),", text).groups()]
        assert volumes == pytest.approx([want, want], rel=1e-12)  # the report prints the real figures
    back = sm.import_step(tmp_path / "a.step")
    assert _volume(solids_of(back.wrapped)[0]) == pytest.approx(want, rel=1e-12)


def test_convert_exits_3_naming_a_solid_the_output_cannot_hold(tmp_path, capsys):
    brep = tmp_path / "open.brep"
    write_brep(_open_shell_solid(), brep)
    assert main(["convert", str(brep), str(tmp_path / "open.step")]) == 3
    text = capsys.readouterr().out
    assert "CHANGED: solids: 1 -> 0" in text and "CHANGED: faces in no solid: 0 -> 5" in text
    assert (tmp_path / "open.step").exists()  # written, and said


@pytest.mark.parametrize("args, said", [
    (["in.stl", "out.step"], "input: .*in.stl is an STL"),
    (["part.step", "out.obj"], "output: .*out.obj has the extension '.obj'"),
    (["missing.brep", "out.step"], "path: no such file"),
    (["part.step", "out.stl", "--tolerance", "0"], "--tolerance: expected a positive length"),
])
def test_convert_bad_input_is_one_line_and_no_file(tmp_path, capsys, args, said):
    (tmp_path / "part.step").write_bytes(PART.read_bytes())
    (tmp_path / "in.stl").write_bytes(b"solid x\nendsolid x\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main(["convert", *(str(tmp_path / a) if "." in a and not a[0].isdigit() else a for a in args)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.match(rf"surfmod convert: error: {said}", err[0]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_convert_to_stl_writes_a_closed_mesh(tmp_path, capsys):
    out = tmp_path / "a.stl"
    assert main(["convert", str(PART), str(out), "--tolerance", "0.05"]) == 0
    assert "triangles" in capsys.readouterr().out
    data = np.frombuffer(out.read_bytes()[84:], dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    assert len(data) > 100
