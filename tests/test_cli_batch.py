"""``surfmod check|mesh PATH...``: folders, CSV rows, bad paths (cli/batch.py)."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

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


# -- folders of ten thousand files: rows kept as files complete, --resume, no orphans -------------
def _copies(tmp_path, count, name="cadquery_red_cube_blue_cylinder.step"):
    folder = tmp_path / "many"
    folder.mkdir()
    for i in range(count):
        shutil.copy(CORPUS / name, folder / f"part{i:02d}.step")
    return folder


def test_check_csv_keeps_finished_files_and_resumes(tmp_path, monkeypatch, capsys):
    """Each file's rows are in the CSV when the next file starts; Ctrl-C during the third
    file keeps the first two; ``--resume`` (after a crash also cut a row in half) checks
    only the files not in the CSV, and the CSV ends with every file's rows once."""
    import surfmod.cli.check as cli_check

    folder, rows_path = _copies(tmp_path, 4), tmp_path / "rows.csv"
    real, seen = cli_check.check_file, []

    def interrupted(path, **kw):
        seen.append(Path(path).name)
        done = {r["file"] for r in csv.DictReader(rows_path.open())} if rows_path.exists() else set()
        assert {Path(f).name for f in done} == set(seen[:-1])  # every finished file is on disk already
        if len(seen) == 3:
            raise KeyboardInterrupt
        return real(path, **kw)

    monkeypatch.setattr(cli_check, "check_file", interrupted)
    args = ["check", str(folder), "--csv", str(rows_path), "--jobs", "1", "--no-progress"]
    with pytest.raises(KeyboardInterrupt):
        main(args)
    first = list(csv.DictReader(rows_path.open()))
    assert {Path(r["file"]).name for r in first} == {"part00.step", "part01.step"} and len(first) == 2 * 9
    with rows_path.open("a") as f:  # a crash in the middle of writing a row
        f.write(str(folder / "part02.step") + ",0,Geom_Pla")
    seen.clear()
    monkeypatch.setattr(cli_check, "check_file", lambda path, **kw: (seen.append(Path(path).name), real(path, **kw))[1])
    assert main([*args, "--resume"]) == 0
    assert seen == ["part02.step", "part03.step"]
    assert "36 of 36 faces passed in 4 file(s) (2 already in" in capsys.readouterr().out
    rows = list(csv.DictReader(rows_path.open()))
    assert len(rows) == 4 * 9 and len({(r["file"], r["face"]) for r in rows}) == 36 and all(r["pass"] == "yes" for r in rows)
    # a resumed run with nothing left to do checks nothing
    seen.clear()
    assert main([*args, "--resume"]) == 0 and seen == []


def test_resume_needs_the_csv_of_the_same_command(tmp_path, capsys):
    folder, rows_path = _copies(tmp_path, 1), tmp_path / "rows.csv"
    assert main(["check", str(folder), "--resume", "--no-progress"]) == 1
    assert "resume: needs --csv" in capsys.readouterr().err
    rows_path.write_text("file,triangles\n")
    assert main(["check", str(folder), "--csv", str(rows_path), "--resume", "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "not a file of this command to resume" in err and err.count("\n") == 1
