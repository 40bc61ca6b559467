"""``surfmod check|mesh PATH...``: folders, CSV rows, bad paths (cli/batch.py)."""

from __future__ import annotations

import csv
import shutil
import time
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
    assert all((r["exit"], r["closed"], r["manifold"], r["outward"], r["repairs"], r["verdict"])
               == ("0", "yes", "yes", "yes", "0", "") for r in rows)
    assert "2 of 2 file(s) meshed, every STL read back as promised; rows in" in capsys.readouterr().out


def test_mesh_folder_rows_carry_each_stl_verdict_and_exit_3(tmp_path, capsys, monkeypatch):
    """A folder run judges each STL as the single-file command does: the file whose STL
    reads back with facets wound against each other and inside out gets exit 3, NO in
    outward, its repairs counted and the broken promise in words in its row (the other
    file's row stays sound), and the run exits 3."""
    import surfmod.io.stl as stl
    from surfmod.meshing.closure import Closure

    folder = _folder(tmp_path)
    real = stl.judge_stl

    def judge(path, groups):  # the STL of b.Stp (the temporary file beside b.stl) reads back broken
        failing = real(path, groups)
        if Path(path).name.startswith(".b.stl"):
            failing = failing + [("solid 1", Closure(0, 0, 4, 0, -2.5, (1, 2)))]
        return failing

    monkeypatch.setattr(stl, "judge_stl", judge)
    rows_path = tmp_path / "mesh.csv"
    args = ["mesh", str(folder), "--tolerance", "0.05", "--csv", str(rows_path), "--no-progress", "--jobs", "1"]
    assert main(args) == 3
    rows = {Path(r["file"]).name: r for r in csv.DictReader(rows_path.open())}
    broken, sound = rows["b.Stp"], rows["A.STEP"]
    assert (broken["exit"], broken["closed"], broken["manifold"], broken["outward"], broken["repairs"]) == \
        ("3", "yes", "yes", "NO", "5")  # 4 edges wound against each other, and the solid turned once
    assert broken["verdict"] == ("solid 1: 4 edge(s) joining facets of opposite orientation; enclosed volume -2.5 "
                                 "(inside out or not closed); along face(s) 1, 2")
    assert (sound["exit"], sound["outward"], sound["repairs"], sound["verdict"]) == ("0", "yes", "0", "")
    out = capsys.readouterr().out
    assert "1 of 2 file(s) meshed, every STL read back as promised; 1 broke a promise (exit 3)" in out
    # without --csv the table says the same, and the exit status does not depend on where rows go
    assert main(args[:4] + args[6:]) == 3
    table = capsys.readouterr().out
    assert "solid 1: 4 edge(s) joining facets of opposite orientation" in table


def test_mesh_folder_exit_1_when_a_file_is_not_meshed(tmp_path, capsys):
    folder = _folder(tmp_path)
    (folder / "broken.step").write_text("ISO-10303-21;\nnot a model\n")
    assert main(["mesh", str(folder), "--tolerance", "0.05", "--csv", str(tmp_path / "m.csv"), "--no-progress",
                 "--jobs", "1"]) == 1
    rows = {Path(r["file"]).name: r for r in csv.DictReader((tmp_path / "m.csv").open())}
    assert rows["broken.step"]["exit"] == "1" and rows["broken.step"]["verdict"].startswith("error: ")
    assert "2 of 3 file(s) meshed, every STL read back as promised; 1 not meshed (exit 1)" in capsys.readouterr().out


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
    assert main(args) == 130
    assert capsys.readouterr().err == "surfmod check: interrupted\n"
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
    assert len(rows) == 4 * 9 and len({(r["file"], r["face"]) for r in rows}) == 36
    assert all(r["pass"] == "yes" for r in rows)
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


def _cli(*args):
    """``surfmod ARGS`` as a separate process (the client a test can kill)."""
    import subprocess
    import sys

    code = "import sys; from surfmod.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.Popen([sys.executable, "-c", code, *map(str, args)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def _command_line(process) -> str:
    """A psutil process's command line, "" once it has gone (it may end while listed)."""
    import psutil

    try:
        return " ".join(process.cmdline())
    except psutil.Error:
        return ""


def _rows_on_disk(path) -> list:
    return list(csv.DictReader(path.open())) if path.exists() else []


def test_killed_client_leaves_no_worker_and_keeps_its_rows(tmp_path):
    """``surfmod check DIR --jobs 2`` killed (SIGKILL) once its first file's rows are on
    disk: its loky workers exit (they watch the client), and the rows of every file it
    finished stay in the CSV, whole."""
    import signal

    psutil = pytest.importorskip("psutil")
    folder, rows_path = _copies(tmp_path, 12), tmp_path / "rows.csv"
    client = _cli("check", folder, "--jobs", 2, "--csv", rows_path, "--no-progress")
    try:
        # waits on the first file (counted in polls; the bound is a last resort for a stuck run)
        for _ in range(3000):
            if _rows_on_disk(rows_path) or client.poll() is not None:
                break
            time.sleep(0.1)
        workers = psutil.Process(client.pid).children(recursive=True)
        assert client.poll() is None and len(workers) >= 2
    finally:
        client.send_signal(signal.SIGKILL)
        client.wait()
    gone, alive = psutil.wait_procs(workers, timeout=60)
    assert not alive, f"{len(alive)} worker(s) outlived their client: {[_command_line(p) for p in alive]}"
    rows = _rows_on_disk(rows_path)
    per_file = {}
    for r in rows:
        per_file[r["file"]] = per_file.get(r["file"], 0) + 1
    assert 1 <= len(per_file) < 12 and set(per_file.values()) == {9}


@pytest.fixture(scope="module")
def cluster():
    """A local Dask cluster of 2 worker processes, one thread each."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        yield c


def test_a_worker_killed_mid_run_loses_no_other_file(tmp_path, cluster):
    """``surfmod check DIR --scheduler`` on 2 workers; one worker is killed (SIGKILL) once
    the first file's rows are on disk and before the last: Dask runs its task again on
    the other, and every file's 9 rows end in the CSV, all passing, exit 0."""
    import os
    import signal

    import distributed

    folder, rows_path = _copies(tmp_path, 8), tmp_path / "rows.csv"
    with distributed.Client(cluster.scheduler_address) as c:
        pids = list(c.run(os.getpid).values())
    client = _cli("check", folder, "--scheduler", cluster.scheduler_address, "--csv", rows_path, "--no-progress")
    try:
        for _ in range(6000):  # polls until the first file is on disk (a last-resort bound)
            if _rows_on_disk(rows_path) or client.poll() is not None:
                break
            time.sleep(0.05)
        finished_at_kill = {r["file"] for r in _rows_on_disk(rows_path)}
        os.kill(pids[0], signal.SIGKILL)
        code = client.wait(timeout=600)
    finally:
        if client.poll() is None:
            client.kill()
    assert 1 <= len(finished_at_kill) < 8
    rows = _rows_on_disk(rows_path)
    per_file = {}
    for r in rows:
        per_file[Path(r["file"]).name] = per_file.get(Path(r["file"]).name, 0) + 1
    assert per_file == {f"part{i:02d}.step": 9 for i in range(8)} and all(r["pass"] == "yes" for r in rows)
    assert code == 0


@pytest.mark.parametrize("flag, value, why", [("--task-seconds", "0.001", "did not finish within 0.001 s"),
                                              ("--task-memory", "0.001", "held more than 0.001 GiB")])
def test_a_task_over_budget_is_named_and_skipped(tmp_path, cluster, capsys, flag, value, why):
    """On a cluster a file whose task goes over its time or memory budget is one row
    naming the file and the budget (its child process killed, the worker spared, no
    retry); the run ends, exit 3 (partial)."""
    folder, rows_path = _copies(tmp_path, 2), tmp_path / "rows.csv"
    assert main(["check", str(folder), "--scheduler", cluster.scheduler_address, flag, value, "--csv", str(rows_path),
                 "--no-progress"]) == 3
    rows = _rows_on_disk(rows_path)
    assert len(rows) == 2 and all(r["face"] == "-1" and r["pass"] == "skip" for r in rows)
    assert all(r["note"] == f"skipped: the task of {r['file']} {why}" for r in rows), rows
    assert "partial: 2 of 2 face(s) could not be checked" in capsys.readouterr().out


def test_mass_folder_rows_and_resume(tmp_path, capsys):
    """``surfmod mass DIR``: one row per file with the volume (a box with a hole: closed
    form) and the verdict; an unreadable file is its own row (exit 1); ``--resume`` keeps
    the rows and measures nothing again."""
    import math

    import build123d as bd

    import surfmod as sm

    folder, rows_path = tmp_path / "parts", tmp_path / "mass.csv"
    folder.mkdir()
    sm.export_step(bd.Box(4, 3, 2) - bd.Cylinder(1, 3), folder / "a.step")
    sm.export_step(bd.Pos(10, 0, 0) * bd.Box(1, 2, 3), folder / "b.step")
    args = ["mass", str(folder), "--csv", str(rows_path), "--jobs", "1", "--no-progress"]
    assert main(args) == 0
    rows = {Path(r["file"]).name: r for r in csv.DictReader(rows_path.open())}
    assert float(rows["a.step"]["volume"]) == pytest.approx(24 - 2 * math.pi, rel=1e-12)
    assert float(rows["b.step"]["cx"]) == pytest.approx(10, rel=1e-12)
    assert float(rows["b.step"]["volume"]) == pytest.approx(6, rel=1e-12)
    assert all(r["exit"] == "0" and r["verdict"].startswith("AGREE") for r in rows.values())
    assert "2 of 2 file(s) settled (exit 0)" in capsys.readouterr().out
    (folder / "c.step").write_text("ISO-10303-21; broken")
    assert main([*args, "--resume"]) == 1
    rows = {Path(r["file"]).name: r for r in csv.DictReader(rows_path.open())}
    assert len(rows) == 3 and rows["c.step"]["exit"] == "1" and rows["c.step"]["verdict"].startswith("error:")
    assert "2 of 3 file(s) settled (exit 0) (2 already in" in capsys.readouterr().out
    # one file, no folder: the command as before
    assert main(["mass", str(folder / "a.step"), "--no-progress"]) == 0
    assert "AGREE" in capsys.readouterr().out


LOCAL_CLUSTER_CLIENT = """
import sys, distributed
from surfmod.cli import main
if __name__ == "__main__":
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        sys.exit(main(["check", sys.argv[1], "--scheduler", c.scheduler_address, "--csv", sys.argv[2],
                       "--no-progress"]))
"""


def test_killed_client_of_its_own_local_cluster_leaves_no_process(tmp_path):
    """A script that starts a local Dask cluster and runs ``surfmod check`` on it, killed
    (SIGKILL) once the first file's rows are on disk: its nannies, workers and the
    workers' surfmod children all end (Dask's nannies watch their parent, surfmod's
    children watch theirs); the finished files' rows stay."""
    import signal
    import subprocess
    import sys

    psutil = pytest.importorskip("psutil")
    pytest.importorskip("distributed")
    folder, rows_path = _copies(tmp_path, 12), tmp_path / "rows.csv"
    script = tmp_path / "client.py"
    script.write_text(LOCAL_CLUSTER_CLIENT)
    client = subprocess.Popen([sys.executable, str(script), str(folder), str(rows_path)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        for _ in range(6000):  # polls until the first file is on disk (a last-resort bound)
            if _rows_on_disk(rows_path) or client.poll() is not None:
                break
            time.sleep(0.05)
        below = psutil.Process(client.pid).children(recursive=True)
        assert client.poll() is None
        assert sum("surfmod.child" in _command_line(p) for p in below) >= 1  # a worker's child is serving
    finally:
        client.send_signal(signal.SIGKILL)
        client.wait()
    gone, alive = psutil.wait_procs(below, timeout=60)
    assert not alive, f"{len(alive)} process(es) outlived their client: {[_command_line(p) for p in alive]}"
    assert 1 <= len({r["file"] for r in _rows_on_disk(rows_path)}) < 12
