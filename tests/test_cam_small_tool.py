"""A small tool on a fine scallop (issue 36: a 24 mm gear with a 1 mm flat and a 0.8 mm
ball, scallop 0.008, gave no answer in 30 minutes): the finishing's work is charged to a
cap estimated before its first drop, refused naming ``--scallop`` (a flag the command
has), its triangle tests shown on a progress bar; the program's moves are written once
for the verification, the file and the verdict in its header."""

import build123d as bd
import pytest

import surfmod as sm
import surfmod.cam.job as job_module
import surfmod.cam.post as post_module
from surfmod.cli import main
from surfmod.errors import SurfmodError


@pytest.fixture(scope="module")
def part_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("small_tool") / "boss.step"
    bd.export_step(bd.Box(12, 10, 4) + bd.Pos(0, 0, 3) * bd.Cylinder(2.5, 2), str(path))
    return path


ARGS = ["--stock-margin", "1", "--rough", "flat:1.5", "--finish", "ball:1", "--scallop", "0.05", "--no-progress"]


def test_finishing_work_refused_before_it_starts(part_file, tmp_path, capsys, monkeypatch):
    drops = []
    original = job_module.finish

    def finish(part, *a, **kw):
        drops.append(part.meter)
        return original(part, *a, **kw)

    monkeypatch.setattr(job_module, "finish", finish)
    monkeypatch.setattr(job_module, "MAX_WORK", 1_000)
    out = tmp_path / "job.ngc"
    assert main(["machine", str(part_file), "--out", str(out), *ARGS]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    # one line naming the command's own flag and the scallop asked for; nothing written,
    # and not one triangle test was spent on the finishing before the refusal
    assert len(err) == 1 and "error: scallop:" in err[0] and "larger scallop than 0.05" in err[0], err
    assert "triangle tests" in err[0] and "max_work" not in err[0]
    assert not out.exists() and len(drops) == 1 and drops[0].used == 0
    with pytest.raises(SurfmodError, match="^scallop:"):
        sm.machine(str(part_file), 1.0, [sm.Finish(sm.Tool("ball", 1.0), scallop=0.05)], verify=False)


def test_finishing_progress_counts_its_tests(part_file, capsys):
    job = sm.machine(str(part_file), 1.0, [sm.Finish(sm.Tool("ball", 1.0), scallop=0.05)], progress=True,
                     verify=False)
    err = capsys.readouterr().err
    # the stage bar and the finishing's own bar of triangle tests (the raster and contours)
    assert "machine" in err and "finishing" in err and " tests" in err
    assert job.operations[0].report["toolpath"].n_passes > 10


def test_program_moves_written_once(part_file, tmp_path, capsys, monkeypatch):
    calls = []
    original = post_module.find_arcs

    def find_arcs(*a, **kw):
        calls.append(len(a[0]))
        return original(*a, **kw)

    monkeypatch.setattr(post_module, "find_arcs", find_arcs)
    monkeypatch.setattr(post_module, "_WRITTEN", {})
    out = tmp_path / "job.ngc"
    assert main(["machine", str(part_file), "--out", str(out), *ARGS]) == 0
    assert "verified:" in out.read_text()
    # verification, the file and its header's verdict: each operation's moves made once
    assert len(calls) == 2, calls
    # the same lines as written afresh (the note is the only difference the header makes)
    job = sm.machine(str(part_file), 1.0, [sm.Finish(sm.Tool("ball", 1.0), scallop=0.05)], verify=False)
    first = post_module.programs(job)[0]
    again = post_module.programs(job, note="judged")[0]
    monkeypatch.setattr(post_module, "_WRITTEN", {})
    assert again.replace("(judged)\n", "") == first == post_module.programs(job)[0]
    assert len(calls) == 4
