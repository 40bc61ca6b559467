"""Cycle time a machine keeps (surfmod.cam.cycle_time) against textbook motion formulas:
a trapezoid ``t = L/v + v/a``, a triangle ``t = 2 sqrt(L/a)``, a stop at a sharp corner,
the junction deviation ``v² = a P cos(φ/2) / (1 - cos(φ/2))``, the centripetal limit
``v = sqrt(a r)`` on a circle of chords, the axis that saturates on a diagonal; and the
machine table refused when it is bad."""

import json
import re

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.cam.cycle_time import cycle_time, feed_time, plan
from surfmod.cam.machine_table import MACHINE, load_machine_table
from surfmod.cam.roughing import FEED, RAPID, Motion
from surfmod.cli import main
from surfmod.errors import SurfmodError

# 100 mm/s, 100 mm/s² on every axis unless a test says otherwise
FAST = sm.Machine(max_velocity=60000, max_acceleration=100, rapid=60000, blend_tolerance=0.0)


def trapezoid(length, v, a, v0=0.0, v1=0.0):
    """The textbook time of one move from ``v0`` to ``v1`` cruising at ``v`` (it reaches ``v``)."""
    d_up, d_down = (v**2 - v0**2) / (2 * a), (v**2 - v1**2) / (2 * a)
    assert d_up + d_down <= length
    return (v - v0) / a + (v - v1) / a + (length - d_up - d_down) / v


def total(points, feed, machine):
    points = np.asarray(points, float)
    return float(plan(points, np.full(len(points) - 1, feed), machine).time.sum())


def test_long_move_is_a_trapezoid():
    # 500 mm at 3000 mm/min = 50 mm/s, a = 100 mm/s²: L/v + v/a
    assert total([[0, 0, 0], [500, 0, 0]], 3000.0, FAST) == pytest.approx(500 / 50 + 50 / 100, rel=1e-12)


def test_short_move_is_a_triangle():
    # 2 mm never reaches 50 mm/s (it would need 25 mm to get there and back)
    p = plan(np.array([[0.0, 0, 0], [0, 2, 0]]), np.array([3000.0]), FAST)
    assert p.time.sum() == pytest.approx(2 * np.sqrt(2 / 100), rel=1e-12)
    assert p.peak[0] == pytest.approx(np.sqrt(100 * 2), rel=1e-12) and p.peak[0] < 50


def test_right_angle_without_tolerance_stops():
    p = plan(np.array([[0.0, 0, 0], [300, 0, 0], [300, 200, 0]]), np.array([3000.0, 3000.0]), FAST)
    assert p.speed[1] == 0.0
    assert p.time.sum() == pytest.approx(trapezoid(300, 50, 100) + trapezoid(200, 50, 100), rel=1e-12)


def test_right_angle_blends_within_the_tolerance():
    # junction deviation: v² = a P cos(45°) / (1 - cos(45°)) (grbl planner.c, LinuxCNC G64 P)
    machine = sm.Machine(max_velocity=60000, max_acceleration=100, blend_tolerance=0.5)
    p = plan(np.array([[0.0, 0, 0], [300, 0, 0], [300, 200, 0]]), np.array([3000.0, 3000.0]), machine)
    c = np.cos(np.pi / 4)
    # the normal of the turn is diagonal: each axis gives 100 along it, the vector 100 sqrt(2)
    v = np.sqrt(100 * np.sqrt(2) * 0.5 * c / (1 - c))
    assert p.speed[1] == pytest.approx(v, rel=1e-12) and v < 50
    assert p.time.sum() == pytest.approx(trapezoid(300, 50, 100, v1=v) + trapezoid(200, 50, 100, v0=v), rel=1e-12)
    # a reversal stops whatever the tolerance
    back = plan(np.array([[0.0, 0, 0], [300, 0, 0], [100, 0, 0]]), np.array([3000.0, 3000.0]), machine)
    assert back.speed[1] == 0.0


def test_collinear_pieces_equal_one_move():
    rng = np.random.default_rng(3)
    t = np.sort(np.concatenate([[0.0, 1.0], rng.random(400)]))
    a, b = np.array([1.0, -2.0, 0.5]), np.array([81.0, 37.0, -4.0])
    pieces = a + t[:, None] * (b - a)
    for machine in (FAST, sm.Machine()):  # no tolerance and the default blending
        one = total([a, b], 1500.0, machine)
        assert total(pieces, 1500.0, machine) == pytest.approx(one, rel=1e-9)
    # the feed-rate sum does not see the pieces either, and is shorter by v/a
    assert one > float(np.linalg.norm(b - a)) / 25.0


@pytest.mark.parametrize("n", [360, 1440])
def test_circle_of_chords_approaches_the_centripetal_limit(n):
    # a circle of radius 10 in chords, X slower to accelerate than Y; feed far above the limit
    r, ax, ay = 10.0, 200.0, 500.0
    machine = sm.Machine(max_velocity=60000, max_acceleration=(ax, ay, 100), blend_tolerance=0.01)
    angle = np.linspace(0, 2 * np.pi, n + 1)
    pts = np.column_stack([r * np.cos(angle), r * np.sin(angle), np.zeros_like(angle)])
    p = plan(pts, np.full(n, 60000.0), machine)
    # at (r, 0) the centripetal acceleration is along X, at (0, r) along Y: v = sqrt(a r)
    # (the blend of a chord polygon has the radius r cos(pi/n): the arc tangent at mid-chords)
    k = n // 4
    assert p.speed[n // 2] == pytest.approx(np.sqrt(ax * r * np.cos(np.pi / n)), rel=1e-9)
    assert p.speed[k] == pytest.approx(np.sqrt(ay * r * np.cos(np.pi / n)), rel=1e-9)
    # between the vertices the speed may rise by at most what a chord allows
    chord = 2 * r * np.sin(np.pi / n)
    most = np.sqrt(np.sqrt(2) * ay * r + ay * chord)
    assert p.peak[n // 8: 3 * n // 8].max() <= most


def test_diagonal_is_limited_by_the_axis_that_saturates():
    # X 6000 mm/min and 500 mm/s², Y 3000 mm/min and 100 mm/s²; a 45° move in XY at 10000 mm/min
    machine = sm.Machine(max_velocity=(6000, 3000, 3000), max_acceleration=(500, 100, 100), rapid=10000)
    length = 400.0
    end = length * np.array([1, 1, 0]) / np.sqrt(2)
    v, a = 50 * np.sqrt(2), 100 * np.sqrt(2)  # Y saturates first on both
    for kind, feed in ((FEED, 10000.0), (RAPID, machine.rapid)):
        motion = Motion(np.array([[0.0, 0, 0], end]), np.array([RAPID, kind], np.int8))
        tool = sm.Tool("flat", 3.0, feed=feed, plunge_feed=100.0)
        job_time = cycle_time(motion, tool, machine)
        assert job_time == pytest.approx(length / v + v / a, rel=1e-12)
        assert feed_time(motion, tool, machine) == pytest.approx(length / feed * 60, rel=1e-12)
    # along X alone the X limits hold
    assert total([[0, 0, 0], [length, 0, 0]], 10000.0, machine) == pytest.approx(length / 100 + 100 / 500, rel=1e-12)


def test_random_path_keeps_every_limit():
    # a random polyline (repeated points, reversals, every axis) checked move by move with
    # the limits recomputed here: rest at both ends, no vertex faster than its moves allow,
    # no speed change beyond what the move's acceleration gives over its length, the
    # profile's time from its own entry, peak and exit speeds, and maximal speeds (a
    # vertex below both neighbours' reach must be held by its own corner)
    rng = np.random.default_rng(7)
    pts = np.cumsum(rng.normal(size=(400, 3)) * rng.choice([0.05, 1.0, 20.0], size=(400, 1)), axis=0)
    pts[50] = pts[49]
    machine = sm.Machine(max_velocity=(6000, 4000, 2000), max_acceleration=(800, 400, 150), blend_tolerance=0.02)
    feeds = rng.choice([300.0, 1500.0, 9000.0], size=len(pts) - 1)
    p = plan(pts, feeds, machine)
    seg = np.diff(pts, axis=0)
    length = np.linalg.norm(seg, axis=1)
    keep = length > 0
    u = seg[keep] / length[keep, None]
    vmax, amax = np.array(machine.max_velocity) / 60, np.array(machine.max_acceleration)
    cruise = np.array([min([f / 60] + [vmax[i] / abs(d[i]) for i in range(3) if d[i]])
                       for f, d in zip(feeds[keep], u)])
    acc = np.array([min(amax[i] / abs(d[i]) for i in range(3) if d[i]) for d in u])
    assert len(p.length) == keep.sum() == len(pts) - 2
    np.testing.assert_allclose(p.cruise, cruise, rtol=1e-12)
    v, w = p.speed, p.speed**2
    assert v[0] == 0 and v[-1] == 0
    assert np.all(v[1:] <= cruise * (1 + 1e-12)) and np.all(v[:-1] <= cruise * (1 + 1e-12))
    assert np.all(np.abs(np.diff(w)) <= 2 * acc * p.length * (1 + 1e-9) + 1e-9)
    assert np.all(p.peak <= cruise * (1 + 1e-12)) and np.all(p.time >= p.length / cruise * (1 - 1e-12))
    up, down = (p.peak**2 - w[:-1]) / (2 * acc), (p.peak**2 - w[1:]) / (2 * acc)
    assert np.all(up + down <= p.length * (1 + 1e-9) + 1e-12)
    expected = (p.peak - v[:-1]) / acc + (p.peak - v[1:]) / acc + (p.length - up - down) / p.peak
    np.testing.assert_allclose(p.time, expected, rtol=1e-9)
    # maximal: an interior vertex strictly below what both moves allow is a corner limit,
    # so it is never above the reach of its neighbours and at least one corner holds it
    reach = np.minimum(np.sqrt(w[:-2] + 2 * acc[:-1] * p.length[:-1]), np.sqrt(w[2:] + 2 * acc[1:] * p.length[1:]))
    held = v[1:-1] < np.minimum(reach, np.minimum(cruise[:-1], cruise[1:])) * (1 - 1e-9)
    turn = np.linalg.norm(u[1:] - u[:-1], axis=1)
    assert held.any() and np.all(turn[held] > 1e-6)


def test_job_estimate_against_the_feed_rate_sum():
    part = bd.Box(20, 20, 5) + bd.Pos(0, 0, 4) * bd.Cylinder(5, 3)
    slow = sm.Machine(max_acceleration=100, tool_change=3)
    job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=2.0, allowance=0.3),
                                 sm.Finish(sm.Tool("ball", 1.5), scallop=0.05)], verify=False, machine=slow)
    assert job.machine is slow and job.time_estimate == sum(op.time_estimate for op in job.operations)
    # a machine with (almost) no limits runs every move at its feed: the two agree
    ideal = sm.Machine(max_velocity=1e9, max_acceleration=1e12, blend_tolerance=1.0)
    for op in job.operations:
        assert op.machine is slow and op.time_estimate > op.feed_time > slow.tool_change
        moves = op.feed_time - slow.tool_change
        assert cycle_time(op.motion, op.tool, ideal) == pytest.approx(moves, rel=1e-3)
        assert cycle_time(op.motion, op.tool, MACHINE) < op.time_estimate - slow.tool_change


@pytest.mark.parametrize("text, word", [
    ('[machine]\nmax_velocity = [5000, 5000]\n', "max_velocity"),
    ('[machine]\nmax_acceleration = [500, 0, 250]\n', "max_acceleration[1]"),
    ('[machine]\nrapid = "fast"\n', "rapid"),
    ('[machine]\nblend_tolerance = -0.1\n', "blend_tolerance"),
    ('[machine]\ntool_change = nan\n', "tool_change"),
    ('[machine]\nmax_jerk = 1000\n', "max_jerk"),
    ('[mill]\nrapid = 3000\n', "[machine]"),
    ('[machine\n', "not a machine table"),
])
def test_bad_machine_tables_refused(tmp_path, text, word):
    path = tmp_path / "mill.toml"
    path.write_text(text)
    with pytest.raises(SurfmodError, match=word.replace("[", r"\[").replace("]", r"\]")):
        load_machine_table(path)


def test_machine_table_json_and_defaults(tmp_path):
    path = tmp_path / "mill.json"
    path.write_text(json.dumps({"machine": {"max_velocity": 8000, "blend_tolerance": 0}}))
    m = load_machine_table(path)
    assert m.max_velocity == (8000.0, 8000.0, 8000.0) and m.blend_tolerance == 0.0
    assert m.max_acceleration == MACHINE.max_acceleration and m.tool_change == MACHINE.tool_change
    with pytest.raises(SurfmodError, match="machine: no such file"):
        load_machine_table(tmp_path / "none.toml")
    with pytest.raises(SurfmodError, match="machine: expected a surfmod Machine"):
        sm.machine(bd.Box(5, 5, 5), 1.0, [sm.Rough(sm.Tool("flat", 1.0))], machine={"rapid": 1})


def test_plan_refuses_bad_input():
    with pytest.raises(SurfmodError, match="feeds: expected one per segment"):
        plan(np.zeros((3, 3)), np.ones(1))
    with pytest.raises(SurfmodError, match="feeds: every feed"):
        plan(np.array([[0.0, 0, 0], [1, 0, 0]]), np.zeros(1))
    with pytest.raises(SurfmodError, match="max_segments"):
        plan(np.zeros((5, 3)), np.ones(4), max_segments=3)


def test_cli_machine_table(tmp_path, capsys):
    part = tmp_path / "part.step"
    bd.export_step(bd.Box(20, 20, 5) + bd.Pos(0, 0, 4) * bd.Cylinder(5, 3), str(part))
    table = tmp_path / "mill.toml"
    table.write_text("[machine]\nmax_acceleration = 50\nblend_tolerance = 0\ntool_change = 20\n")
    out = tmp_path / "job.ngc"
    argv = ["machine", str(part), "--out", str(out), "--stock-margin", "2", "--rough", "flat:3", "--finish",
            "ball:1.5", "--scallop", "0.1", "--no-verify", "--no-progress"]
    assert main(argv + ["--machine", str(table)]) == 0
    text = capsys.readouterr().out
    slow = [float(x) for x in re.findall(r"time estimate ([\d.]+) s \(feed-rate sum ([\d.]+) s\)",
                                                       text)[0]]
    assert slow[0] > slow[1] > 20
    assert "machine: axes 5000/5000/3000 mm/min, 50/50/50 mm/s², rapid 5000 mm/min, blending 0 mm" in text
    table.write_text("[machine]\nmax_acceleration = [500, 500, 0]\n")
    out.unlink()
    assert main(argv + ["--machine", str(table)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "max_acceleration[2]" in err[0] and not out.exists()
