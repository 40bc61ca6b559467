"""Machining from stock: a part with a pocket and a boss roughed and finished, the program
read back by LinuxCNC's own interpreter (``rs274 -g``), the moves checked against the part
by an independent sampling of the tool over the part's mesh points."""

import re
import shutil
import subprocess

import build123d as bd
import numpy as np
import pytest
from scipy.spatial import cKDTree

import surfmod as sm
from surfmod.cli import main
from surfmod.cam.roughing import FEED, MAX_RAMP_ANGLE, RAPID
from surfmod.cam.drop_cutter import part_triangles

RS274 = shutil.which("rs274")
needs_rs274 = pytest.mark.skipif(RS274 is None, reason="rs274 (Debian package linuxcnc-uspace) is not installed")


def pocket_part():
    part = bd.Box(24, 16, 6) - bd.Pos(3, 0, 2) * bd.Box(10, 8, 3)
    return part + bd.Pos(-7, 0, 4) * bd.Cylinder(2.5, 2)


@pytest.fixture(scope="module")
def part_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cam") / "pocket.step"
    bd.export_step(pocket_part(), str(path))
    return path


@pytest.fixture(scope="module")
def job(part_file):
    return sm.machine(str(part_file), 2.0, [sm.Rough(sm.Tool("flat", 2.0), stepdown=1.5, allowance=0.3),
                                            sm.Finish(sm.Tool("ball", 1.0), scallop=0.05)])


def canon(path):
    """The canonical machine commands rs274 reads from ``path``: (name, numbers) tuples."""
    out = path.with_suffix(".canon")
    run = subprocess.run([RS274, "-g", str(path), str(out)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr
    text = out.read_text()
    assert "error" not in (run.stdout + run.stderr).lower(), run.stdout + run.stderr
    cmds = []
    for line in text.splitlines():
        m = re.match(r"\s*\d+\s+N\.+\s+([A-Z_0-9]+)\((.*)\)", line)
        if m:
            nums = [float(v) for v in re.findall(r"-?\d+\.\d+|-?\d+", m.group(2))] if m.group(1) != "COMMENT" else []
            cmds.append((m.group(1), nums))
    return cmds


def program_moves(job, digits=4):
    """The job's moves as written (heights rounded up), consecutive repeats dropped."""
    out = []
    for op in job.operations:
        p = op.motion.points.copy()
        p[:, 2] = np.ceil(np.round(p[:, 2] * 10**digits, 6)) / 10**digits
        p[:, :2] = np.round(p[:, :2], digits)
        for q in p:
            if not out or np.any(np.abs(out[-1] - q) > 1e-9):
                out.append(q)
    return np.array(out)


@needs_rs274
def test_linuxcnc_program_runs_in_rs274(job, tmp_path):
    path = tmp_path / "job.ngc"
    # straight moves only, so that every move read back is one of the job's (the rings
    # round the boss are circles, written as G2/G3 by default: tests/test_cam_arcs.py)
    sm.export_gcode(job, path, post="linuxcnc", arcs=False)
    text = path.read_text()
    assert not re.search(r"\bG(28|30|53|5)\b", text)
    cmds = canon(path)
    names = [c[0] for c in cmds]
    assert names.count("CHANGE_TOOL") == 2
    assert [c[1][0] for c in cmds if c[0] == "CHANGE_TOOL"] == [1, 2]
    assert names[-3:].count("PROGRAM_END") == 1 or "PROGRAM_END" in names
    # per tool: change, length offset, spindle on before the first feed, spindle off after the last
    spindle, tool = False, None
    for name, nums in cmds:
        if name == "CHANGE_TOOL":
            tool, offset_seen = int(nums[0]), False
        elif name == "USE_TOOL_LENGTH_OFFSET" and tool is not None:
            offset_seen = True
        elif name == "START_SPINDLE_CLOCKWISE":
            spindle = True
        elif name == "STOP_SPINDLE_TURNING":
            spindle = False
        elif name in ("STRAIGHT_FEED", "ARC_FEED"):
            assert spindle and tool is not None and offset_seen, "a cut without spindle, tool or G43"
    assert not spindle
    # the moves read back are the job's moves
    moves = np.array([c[1][:3] for c in cmds if c[0] in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")])
    ref = program_moves(job)
    assert len(moves) >= len(ref) - 2
    tree = cKDTree(moves)
    d, _ = tree.query(ref)
    assert d.max() < 2e-4


@needs_rs274
def test_grbl_one_program_per_tool(job, tmp_path):
    paths = sm.export_gcode(job, tmp_path / "job.nc", post="grbl")
    assert [p.name for p in paths] == ["job_T1.nc", "job_T2.nc"]
    for p in paths:
        text = p.read_text()
        assert "M6" not in text and "G43" not in text and "M3" in text and "M30" in text
        names = [c[0] for c in canon(p)]
        assert names.index("START_SPINDLE_CLOCKWISE") < names.index("STRAIGHT_FEED")


def part_points(job):
    tri, _ = part_triangles(job.part, 0.01)
    pts = np.concatenate([tri.reshape(-1, 3), tri.mean(axis=1)])
    return np.unique(np.round(pts, 9), axis=0)


def sample_moves(points, spacing):
    seg = np.diff(points, axis=0)
    n = np.maximum(np.ceil(np.linalg.norm(seg[:, :2], axis=1) / spacing).astype(int), 1)
    t = np.concatenate([np.arange(k) / k for k in n])
    return np.vstack([np.repeat(points[:-1], n, axis=0) + np.repeat(seg, n, axis=0) * t[:, None], points[-1:]])


def deepest_cut(tool, locations, pts, allowance):
    """Deepest any part point lies inside the tool grown by ``allowance`` (> 0: a gouge)."""
    tree = cKDTree(pts[:, :2])
    reach = tool.radius + allowance
    worst = -np.inf
    for q, near in zip(locations, tree.query_ball_point(locations[:, :2], reach)):
        if not near:
            continue
        p = pts[near]
        d = np.hypot(p[:, 0] - q[0], p[:, 1] - q[1])
        # the tool grown by the allowance: the profile of the tool, widened by it, dropped by it
        r = np.maximum(d - allowance, 0.0)
        lift = tool.profile(np.minimum(r, tool.radius))
        worst = max(worst, float((p[:, 2] - (q[2] - allowance + lift)).max()))
    return worst


def test_roughing_never_enters_the_allowance(job):
    rough = job.operations[0]
    pts = part_points(job)
    cuts = sample_moves(rough.motion.points, 0.2)
    # the grown flat end: a point at horizontal d > R lies beside the tool, within A of its rim
    depth = deepest_cut(rough.tool, cuts, pts, 0.0)
    assert depth <= 1e-3  # the mesh's chordal deflection
    # and the allowance itself: no part point under the flat end grown by A (a wall point
    # at exactly R + A beside the axis is where the grown rim touches it)
    tree = cKDTree(pts[:, :2])
    worst = -np.inf
    for q, near in zip(cuts, tree.query_ball_point(cuts[:, :2], rough.tool.radius + 0.3 - 1e-3)):
        if near:
            worst = max(worst, float((pts[near, 2] - q[2]).max()))
    assert worst <= -0.3 + 1e-3


def test_finishing_never_gouges(job):
    fin = job.operations[1]
    cuts = sample_moves(fin.motion.points, 0.05)
    depth = deepest_cut(fin.tool, cuts, part_points(job), 0.0)
    assert depth <= fin.report["tolerance"] + 1e-6


def test_entries_and_links(job):
    safe = job.safe_height
    for op in job.operations:
        p, kind = op.motion.points, op.motion.kind
        seg = np.diff(p, axis=0)
        rapid = kind[1:] == RAPID
        level = np.hypot(seg[:, 0], seg[:, 1]) > 1e-9
        # rapids across run at the clearance height; others are vertical
        assert np.all(np.abs(p[1:][rapid & level, 2] - safe) < 1e-9)
        assert np.all(np.abs(p[:-1][rapid & level, 2] - safe) < 1e-9)
        if op.tool.kind != "ball":
            # no straight plunge of a flat end below the stock top, ramps no steeper than the limit
            # (descents of cutting moves below 0.05 mm are lifts onto the exact height where the
            # grid put a ring a fraction of a cell into the allowance)
            cut = ~rapid & (seg[:, 2] < -0.05) & (p[1:, 2] < job.stock[1, 2])
            slope = -seg[cut, 2] / np.maximum(np.hypot(seg[cut, 0], seg[cut, 1]), 1e-300)
            assert np.all(slope <= np.tan(np.radians(MAX_RAMP_ANGLE)) + 1e-9)
    assert job.operations[0].motion.kind.tolist().count(FEED) > 100


def test_roughing_clears_to_the_allowance(job):
    """Over the open floor beside the part the roughing reaches the stock bottom, and over the
    pocket floor its lowest level stands on floor + allowance."""
    p = job.operations[0].motion.points
    assert abs(p[:, 2].min() - job.stock[0, 2]) < 1e-9
    in_pocket = (np.abs(p[:, 0] - 3) < 5 - 2 - 0.3 - 1e-6) & (np.abs(p[:, 1]) < 4 - 2 - 0.3 - 1e-6)
    assert abs(p[in_pocket, 2].min() - (0.5 + 0.3)) < 1e-6


def test_summary_and_times(job):
    text = str(job)
    assert "roughing" in text and "finishing" in text and "T1" in text and "T2" in text
    for op in job.operations:
        assert op.time_estimate > 0 and op.length > 0


def test_cli_machine(part_file, tmp_path, capsys):
    out = tmp_path / "job.ngc"
    png = tmp_path / "job.png"
    assert main(["machine", str(part_file), "--out", str(out), "--stock-margin", "2", "--rough", "flat:2",
                 "--finish", "ball:1", "--scallop", "0.08", "--stepdown", "2", "--allowance", "0.3",
                 "--png", str(png), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "roughing" in text and "time estimate" in text and out.is_file()
    # the finishing passes and the rest left: levels, contours, the pocket's corners
    assert "waterline on slopes >= 45 deg:" in text and "contours" in text and "raster:" in text
    assert "rest not reached" in text and "max depth" in text
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert "T1 M6" in out.read_text() and "T2 M6" in out.read_text()


@pytest.mark.parametrize("args, word", [
    (["--rough", "flat:0"], "radius"),
    (["--rough", "bull:2:2"], "corner_radius"),
    (["--stepdown", "0"], "stepdown"),
    (["--scallop", "1"], "scallop"),
    (["--post", "fanuc"], "post"),
    (["--stock", "-1", "-1", "-1", "1", "1", "1"], "stock"),
])
def test_cli_bad_input(part_file, tmp_path, capsys, args, word):
    out = tmp_path / "bad.ngc"
    base = {"--rough": ["flat:2"], "--finish": ["ball:1"], "--scallop": ["0.08"], "--stock-margin": ["2"]}
    for k in range(len(args)):
        if args[k].startswith("--"):
            base.pop(args[k], None)
            if args[k] == "--stock":
                base.pop("--stock-margin", None)
    argv = ["machine", str(part_file), "--out", str(out), "--no-progress"]
    for k, v in base.items():
        argv += [k, *v]
    argv += args
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0]
    assert not out.exists()


def test_no_solid(tmp_path, capsys):
    path = tmp_path / "face.step"
    bd.export_step(bd.Face.make_rect(10, 10), str(path))
    assert main(["machine", str(path), "--out", str(tmp_path / "x.ngc"), "--stock-margin", "2", "--rough",
                 "flat:2", "--finish", "ball:1", "--scallop", "0.05", "--no-progress"]) == 1
    assert not (tmp_path / "x.ngc").exists()


@pytest.mark.parametrize("target, value, flag", [
    ("surfmod.cam.job.MAX_WORK", 1000, "--scallop"),             # the finishing's drop-cutter work
    ("surfmod.cam.toolpath.MAX_TRIANGLES", 10, "--allowance"),   # the roughing's mesh, the first stage
    ("surfmod.cam.verify.MAX_PROBES", 10, "--no-verify"),        # the verification's probes
])
def test_cli_a_stage_cap_names_a_flag_the_command_has(part_file, tmp_path, capsys, monkeypatch, target, value,
                                                      flag):
    """Issue 36: every stage estimates its work before it starts and refuses above its cap
    in one line naming an option the command has (not the inner functions' max_work,
    tolerance, max_probes).  The caps are lowered here so that a small part meets them."""
    import surfmod.cam.verify as verify_module

    monkeypatch.setattr(target, value)
    # verify_job's default cap was bound when it was defined
    monkeypatch.setattr(verify_module.verify_job, "__kwdefaults__",
                        dict(verify_module.verify_job.__kwdefaults__, max_probes=verify_module.MAX_PROBES))
    with pytest.raises(SystemExit):
        main(["machine", "--help"])
    assert flag in capsys.readouterr().out
    out = tmp_path / "capped.ngc"
    argv = ["machine", str(part_file), "--out", str(out), "--stock-margin", "2", "--rough", "flat:2",
            "--finish", "ball:1", "--scallop", "0.08", "--no-progress"]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    keyword = flag.removeprefix("--no-").removeprefix("--")
    assert len(err) == 1 and f"error: {keyword}: the " in err[0], err
    assert flag != "--no-verify" or "--no-verify" in err[0]
    assert not out.exists()


def test_the_progress_bar_moves_through_the_stages(part_file, capsys):
    """Issue 36: the bar names each stage as it starts, counts the waterline's levels and
    the finishing's drop-cutter work, and ends at its total."""
    sm.machine(str(part_file), 2.0, [sm.Rough(sm.Tool("flat", 2.0), stepdown=1.5, allowance=0.3),
                                     sm.Finish(sm.Tool("ball", 1.0), scallop=0.08)], progress=True)
    err = capsys.readouterr().err
    for stage in ("roughing's mesh", "roughing", "finishing", "verification"):
        assert f"stage/s, {stage}]" in err or f"stage, {stage}]" in err or f", {stage}]" in err, stage
    levels = re.findall(r"waterline level (\d+)/(\d+)", err)
    assert levels and levels[-1][0] == levels[-1][1] and int(levels[-1][1]) > 1
    assert re.search(r"finishing: +\d+%.*[1-9][\d.]*[kM]? tests", err)
    assert "5/5" in err


def test_a_finishing_mesh_refused_before_any_operation_runs(monkeypatch):
    """A scallop whose mesh tolerance (a tenth of it) lies below 1e-6 of a 1.2 m part is
    refused before the roughing starts, in one line naming the scallop."""
    import surfmod.cam.job as job_module

    def no_roughing(*args, **kwargs):
        raise AssertionError("the roughing ran before the finishing's refusal")

    monkeypatch.setattr(job_module, "rough", no_roughing)
    rail = bd.Box(40, 40, 1200)
    with pytest.raises(sm.SurfmodError) as err:
        sm.machine(rail, 2.0, [sm.Rough(sm.Tool("flat", 2.0)), sm.Finish(sm.Tool("ball", 1.0), scallop=0.01)])
    text = str(err.value)
    assert text.startswith("scallop: the finishing's mesh (tolerance): 0.001 is below") and "\n" not in text, text


@pytest.mark.parametrize("finish, message", [
    (sm.Finish(sm.Tool("flat", 1.0), scallop=0.05), "scallop: a flat end mill leaves no scallop"),
    (sm.Finish(sm.Tool("ball", 1.0), scallop=-0.1), "scallop: must be a finite number > 0, got -0.1"),
    (sm.Finish(sm.Tool("ball", 1.0), scallop=1.5), "scallop: must be smaller than the tool radius 1"),
    (sm.Finish(sm.Tool("ball", 1.0), stepover=2.5), "stepover: 2.5 is larger than the tool diameter 2"),
    (sm.Finish(sm.Tool("ball", 1.0), scallop=0.1, direction="z"), "direction: expected 'x' or 'y'"),
])
def test_a_scallop_the_tool_cannot_leave_is_refused_before_the_roughing(monkeypatch, finish, message):
    """The finishing's stepover or scallop is checked against its tool as ``sm.toolpath``
    checks it (one function), before any operation runs, naming the option to change."""
    import surfmod.cam.job as job_module

    def no_roughing(*args, **kwargs):
        raise AssertionError("the roughing ran before the finishing's refusal")

    monkeypatch.setattr(job_module, "rough", no_roughing)
    with pytest.raises(sm.SurfmodError) as err:
        sm.machine(bd.Box(10, 10, 4), 2.0, [sm.Rough(sm.Tool("flat", 2.0)), finish])
    assert str(err.value).startswith(message), str(err.value)
    if finish.scallop is not None and finish.direction == "x":
        with pytest.raises(sm.SurfmodError, match="^" + re.escape(message)):
            sm.toolpath(bd.Box(10, 10, 4), finish.tool, scallop=finish.scallop)


def test_each_mesh_estimate_is_surveyed_once_before_its_meshing(monkeypatch):
    """The up-front check's curvature estimate is passed to the operation's meshing, not
    surveyed again (0.4 s each on the 280 mm mould): one survey per roughing and finishing
    besides the mesher's own."""
    import surfmod.cam.toolpath as toolpath_module

    calls = []
    survey = toolpath_module.triangle_estimate
    monkeypatch.setattr(toolpath_module, "triangle_estimate", lambda *a, **k: calls.append(a[1]) or survey(*a, **k))
    sm.machine(pocket_part(), 2.0, [sm.Rough(sm.Tool("flat", 2.0), stepdown=1.5, allowance=0.3),
                                    sm.Finish(sm.Tool("ball", 1.0), scallop=0.05)], verify=False)
    assert len(calls) == 2 and calls[0] != calls[1], calls


def test_cli_a_flat_finishing_takes_a_stepover(tmp_path, capsys):
    """A flat end mill leaves no scallop: the command finishes with it by ``--stepover``, the
    flag its refusal of ``--scallop`` names, and takes one of the two, not both."""
    part, out = tmp_path / "step.step", tmp_path / "flat.ngc"
    bd.export_step(bd.Box(8, 6, 3) - bd.Pos(1.5, 0, 1) * bd.Box(3, 6, 1), str(part))
    argv = ["machine", str(part), "--out", str(out), "--stock-margin", "1", "--rough", "flat:1.5",
            "--finish", "flat:1", "--no-progress"]
    assert main(argv + ["--scallop", "0.05"]) == 1
    assert "give stepover instead" in capsys.readouterr().err and not out.exists()
    with pytest.raises(SystemExit) as usage:  # argparse: one of the two
        main(argv + ["--scallop", "0.05", "--stepover", "0.8"])
    assert usage.value.code == 2 and "not allowed with argument --scallop" in capsys.readouterr().err
    assert main(argv + ["--stepover", "1.5"]) == 0
    text = capsys.readouterr().out
    assert "verified" in out.read_text() and "T2 M6" in out.read_text() and "finishing" in text
