"""``surfmod check|mesh PATH...``: folders, CSV rows, bad paths (cli/batch.py)."""

from __future__ import annotations

import csv
import shutil

import pytest

from conftest import CORPUS
from surfmod.cli import main
from surfmod.cli.batch import step_files


def _folder(tmp_path):
    (tmp_path / "in" / "deep").mkdir(parents=True)
    shutil.copy(CORPUS / "cadquery_red_cube_blue_cylinder.step", tmp_path / "in" / "deep" / "A.STEP")
    shutil.copy(CORPUS / "pythonocc_face_recognition_sample_part.stp", tmp_path / "in" / "b.Stp")
    (tmp_path / "in" / "readme.txt").write_text("not a part")
    return tmp_path / "in"


def test_step_files_recursive_any_case(tmp_path):
    names = [p.name for p in step_files([_folder(tmp_path)])]
    assert names == ["b.Stp", "A.STEP"] or sorted(names) == ["A.STEP", "b.Stp"]


def test_mesh_folder_to_csv(tmp_path, capsys):
    folder = _folder(tmp_path)
    rows_path = tmp_path / "mesh.csv"
    assert main(["mesh", str(folder), "--tolerance", "0.05", "--csv", str(rows_path), "--no-progress", "--jobs", "1"]) == 0
    rows = list(csv.DictReader(rows_path.open()))
    assert len(rows) == 2 and all(r["watertight"] == "yes" and int(r["triangles"]) > 0 for r in rows)
    assert all((folder / r["stl"]).exists() or shutil.os.path.exists(r["stl"]) for r in rows)
    assert "2 of 2 file(s) meshed watertight" in capsys.readouterr().out


@pytest.mark.parametrize("command", ["check", "mesh"])
def test_folder_without_step_files_exits_1(tmp_path, capsys, command):
    (tmp_path / "notes.txt").write_text("x")
    assert main([command, str(tmp_path), "--csv", str(tmp_path / "rows.csv"), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "no STEP file" in err and err.count("\n") == 1 and not (tmp_path / "rows.csv").exists()
