"""Seeded fuzzing of the error contract (issue "Reliability").

Hostile arguments, drawn from a seeded generator, go through constructors, evaluation and
operations.  Every case must end in a result whose numbers are all finite, or in a
``SurfmodError``/``KernelError`` whose message starts with the name of an argument; a raw
exception, a non-finite result or a hang (over ``CASE_SECONDS``) fails the test with the
list of offending cases.

The default run (CI) checks the same 2,000 API cases every time; with
``HYPOTHESIS_PROFILE=explore`` (the suite's profile switch) it draws 10,000 new ones from a
fresh seed, printed with any failure for replay through ``SURFMOD_FUZZ_SEED``.  STEP files
damaged by :mod:`tests.step_mutations` are read by :func:`surfmod.import_step` and run
through the six commands in a child process (``tests/fuzz_driver.py``), so an OCCT crash
is a failed case, not a dead test run; the default run takes a sample, ``-m corpus``
every corpus file.
"""

from __future__ import annotations

import json
import math
import os
import re
import select
import signal
import subprocess
import sys
from pathlib import Path

import build123d as bd
import numpy as np
import pytest
from conftest import CORPUS_FILES, JUDGED_FILES
from step_mutations import KINDS, mutate

import surfmod as sm
from surfmod.cam.toolpath import drop_cutter
from surfmod.curve import Curve
from surfmod.surface import Surface

EXPLORE = os.environ.get("HYPOTHESIS_PROFILE") == "explore"
SEED = int(os.environ.get("SURFMOD_FUZZ_SEED", int.from_bytes(os.urandom(4), "little") if EXPLORE else 20261127))
SCALE = 5 if EXPLORE else 1
# The alarm tells a hang (a loop that never ends) from slow work, so it sits far above any
# case's time: the first case of a kind in a worker loads or compiles its numba kernels,
# and on a 2-core machine loaded 4x over an export_stl case took over 20 s (a limit of 20
# failed a run of the whole suite there).  Cases take well under a second when warm.
CASE_SECONDS = 120.0
# tracing two many-span NURBS (the superellipsoid has 20 x 40 spans) against each other
# takes ~10 s alone on a busy 2-core machine: slow, but it ends
SLOW_CASES = {"intersect surfaces": 300.0}
# "name: ...", "name[0] (u): ...", "u, v: ...", "b origin: ..." -- the argument comes first
NAMED = re.compile(r"^[A-Za-z_]\w*(\[\d+\])?( \(\w+\))?( origin| normal|\.\w+)?(, [A-Za-z_]\w*)*: \S")


class Hang(BaseException):
    """Raised by the alarm; a BaseException so that no ``except Exception`` swallows it."""


def _alarm(signum, frame):
    raise Hang


# -- hostile values ---------------------------------------------------------------------------
BAD_NUMBERS = [0.0, -1.0, -1e-300, math.nan, math.inf, -math.inf, 1e300, -1e300, 1e71, 10**400, -(10**400),
               10**20, True, None, "a", "1.0", [1, 2], [], np.array([1.0, 2.0]), np.zeros((2, 2)), 1j,
               object(), b"\xff"]
BAD_INTS = [0, -1, 10**20, 10**400, 2.5, True, "3", None, np.int64(-5), math.nan, [3], 1e9]
BAD_POINTS = [(0, 0, 0), (1e300, 1e300, 1e300), (math.nan, 0, 0), (1, 2), (1, 2, 3, 4), "abc", [[1, 2, 3]],
              np.zeros((2, 3)), [1, "a", 2], [[1, 2], [3]], None, (10**400, 0, 0), (1e-320, 0, 0), 5.0]


def number(rng, low=0.1, high=10.0):
    if rng.random() < 0.6:
        return float(rng.uniform(low, high)) * (1 if rng.random() < 0.9 else -1)
    return BAD_NUMBERS[rng.integers(len(BAD_NUMBERS))]


def integer(rng, low=2, high=12):
    if rng.random() < 0.65:
        return int(rng.integers(low, high))
    return BAD_INTS[rng.integers(len(BAD_INTS))]


def point(rng, scale=3.0):
    if rng.random() < 0.7:
        return tuple(rng.uniform(-scale, scale, 3))
    return BAD_POINTS[rng.integers(len(BAD_POINTS))]


def params(rng, lo, hi):
    """A parameter argument for a domain: scalars and arrays inside it, or hostile ones."""
    r = rng.random()
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = -1.0, 1.0
    if r < 0.35:
        return float(rng.uniform(lo, hi))
    if r < 0.6:
        shape = [(4,), (3, 1), (2, 3), (1,), (5,)][rng.integers(5)]
        return rng.uniform(lo, hi, shape)
    bad = [np.zeros(0), [], lo - 1.0 - abs(hi - lo), hi + 10.0, math.nan, [[lo, hi], [lo]], "0.5",
           np.array([object(), 1.0], dtype=object), np.array([lo, hi], dtype=object), 1e300, 10**400,
           np.full((2, 2, 2), lo), [lo, hi, math.inf], np.array([1j])]
    return bad[rng.integers(len(bad))]


# -- valid objects to operate on ------------------------------------------------------------
def _surfaces():
    rng = np.random.default_rng(7)
    net = rng.uniform(-1, 1, (4, 4, 3))
    net[..., 0] += np.arange(4)[:, None]
    net[..., 1] += np.arange(4)[None, :]
    return [
        sm.sphere(2.0),
        sm.torus(3.0, 1.0),
        sm.ellipsoid(1.0, 2.0, 3.0),
        sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)),
        sm.BezierSurface(net),
        sm.BSplineSurface(rng.uniform(-1, 1, (5, 4, 3)) + np.arange(5)[:, None, None], (2, 2)),
        sm.superellipsoid(1.0, 1.5, 2.0, 0.5, 2.0),
        sm.revolution(sm.Line((1, 0, 0), (2, 0, 3))),
        sm.tabulated_cylinder(sm.Circle((0, 0, 0), (0, 0, 1), 1.0), (0, 0, 1), 2.0),
    ]


def _curves():
    return [
        sm.Line((0, 0, 0), (1, 2, 3)),
        sm.Circle((0, 0, 0), (0, 0, 1), 2.0),
        sm.Arc((0, 0, 0), (0, 0, 1), 1.0, 10, 200),
        sm.BezierCurve([(0, 0, 0), (1, 2, 0), (2, 0, 1)]),
        sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 1)], 2),
    ]


SURFACES = _surfaces()
CURVES = _curves()


def any_surface(rng):
    if rng.random() < 0.9:
        return SURFACES[rng.integers(len(SURFACES))]
    return ["s", None, 3.0, CURVES[0], np.zeros((3, 3, 3))][rng.integers(5)]


def any_curve(rng):
    if rng.random() < 0.9:
        return CURVES[rng.integers(len(CURVES))]
    return ["c", None, 3.0, SURFACES[0], [(0, 0, 0), (1, 1, 1)]][rng.integers(5)]


# -- the cases -------------------------------------------------------------------------------
def constructor_case(rng):
    k = rng.integers(14)
    if k == 0:
        a = (number(rng), point(rng))
        return "sphere", lambda: sm.sphere(*a)
    if k == 1:
        a = (number(rng, 2, 5), number(rng, 0.1, 1.5))
        return "torus", lambda: sm.torus(*a)
    if k == 2:
        a = (number(rng), number(rng), number(rng), point(rng))
        return "ellipsoid", lambda: sm.ellipsoid(*a)
    if k == 3:
        a = (number(rng), number(rng), number(rng), number(rng, 0.2, 3), number(rng, 0.2, 3))
        return "superellipsoid", lambda: sm.superellipsoid(*a)
    if k == 4:
        a = (point(rng), point(rng), number(rng))
        return "Circle", lambda: sm.Circle(*a)
    if k == 5:
        a = (point(rng), point(rng), number(rng), number(rng, -360, 360), number(rng, -360, 720))
        return "Arc", lambda: sm.Arc(*a)
    if k == 6:
        a = (point(rng), point(rng))
        return "Line", lambda: sm.Line(*a)
    if k == 7:
        a = (any_curve(rng), point(rng), number(rng))
        return "tabulated_cylinder", lambda: sm.tabulated_cylinder(*a)
    if k == 8:
        a = (any_curve(rng), point(rng), point(rng), number(rng, 1, 360))
        return "revolution", lambda: sm.revolution(*a)
    if k == 9:
        a = (SURFACES[rng.integers(len(SURFACES))], point(rng), point(rng), number(rng, -720, 720))
        return "rotated", lambda: a[0].rotated(*a[1:])
    if k == 10:
        net = rng.uniform(-2, 2, (int(rng.integers(2, 6)), int(rng.integers(2, 6)), 3))
        if rng.random() < 0.4:
            net = [net, np.zeros((2, 2)), [[[0, 0, 0]]], net * 1e300, np.where(net > 1.5, np.nan, net), "net"][rng.integers(6)]
        return "BezierSurface", lambda: sm.BezierSurface(net)
    if k == 11:
        n = int(rng.integers(2, 7))
        pts = rng.uniform(-2, 2, (n, 3))
        a = (pts, integer(rng, 1, n))
        return "BSplineCurve", lambda: sm.BSplineCurve(*a)
    if k == 12:
        a = (point(rng), point(rng), point(rng))
        return "plane", lambda: sm.plane(*a)
    a = (any_curve(rng), sm.Line((0, 0, 0), (0, 0, 5)) if rng.random() < 0.8 else any_curve(rng), number(rng, -720, 720))
    return "sweep", lambda: sm.sweep(a[0], a[1], twist=a[2])


def evaluation_case(rng):
    k = rng.integers(8)
    if k < 5:
        s = SURFACES[rng.integers(len(SURFACES))]
        (u0, u1), (v0, v1) = s.domain
        u, v = params(rng, u0, u1), params(rng, v0, v1)
        if k == 0:
            return f"{type(s).__name__}.points", lambda: s.points(u, v)
        if k == 1:
            order = integer(rng, 0, 4)
            return f"{type(s).__name__}.derivatives", lambda: s.derivatives(u, v, order)
        if k == 2:
            return f"{type(s).__name__}.grid", lambda: s.grid(u, v)
        if k == 3:
            return f"{type(s).__name__}.normals", lambda: s.normals(u, v)
        return f"{type(s).__name__}.curvatures", lambda: s.curvatures(u, v)
    c = CURVES[rng.integers(len(CURVES))]
    t = params(rng, *c.domain)
    if k == 5:
        return f"{type(c).__name__}.points", lambda: c.points(t)
    if k == 6:
        order = integer(rng, 0, 4)
        return f"{type(c).__name__}.derivatives", lambda: c.derivatives(t, order)
    return f"{type(c).__name__}.tangents", lambda: c.tangents(t)


def operation_case(rng, tmp: Path):
    k = rng.integers(100)
    s = any_surface(rng)
    if k < 30:
        pts = [rng.uniform(-4, 4, (int(rng.integers(1, 20)), 3)), point(rng), [[0, 0, 1e300]], [[0, 0, 1e60]],
               np.zeros((0, 3)), [[1, 2]], "p", any_curve(rng)][rng.integers(8)]
        return "project", lambda: sm.project(pts, s)
    if k < 50:
        a = (s, integer(rng, 2, 30), integer(rng, 2, 30))
        return "mesh", lambda: sm.mesh(*a)
    if k < 60:
        origin, normal = point(rng, 1.0), point(rng)
        plane = (origin, normal) if rng.random() < 0.7 else ["plane", None, (origin,), origin][rng.integers(4)]
        tol = number(rng, 1e-7, 1e-5)
        return "intersect plane", lambda: sm.intersect(s, plane, tol)
    if k < 64:
        b = SURFACES[rng.integers(len(SURFACES))] if rng.random() < 0.5 else s
        tol = number(rng, 1e-7, 1e-5)
        return "intersect surfaces", lambda: sm.intersect(s, b, tol)
    if k < 72:
        a = (s, point(rng, 1.0), point(rng))
        return "intersect_line", lambda: sm.intersect_line(*a)
    if k < 77:
        tol = number(rng, 0.05, 0.5)
        return "tessellate", lambda: sm.tessellate(s, tol)
    if k < 87:
        name = ["a" * 300 + ".step", "x.step", "no/such/dir/x.step", "", "x.txt", 3, None, tmp, "\x00.step",
                "é" * 130 + ".step"][rng.integers(10)]
        target = tmp / name if isinstance(name, str) and name and rng.random() < 0.5 else name
        return "export_step", lambda: sm.export_step(s, target)
    if k < 92:
        tol = number(rng, 0.05, 0.5)
        return "export_stl", lambda: sm.export_stl(s, tmp / "f.stl", tolerance=tol)
    a = (point(rng), point(rng), number(rng))
    s = SURFACES[rng.integers(len(SURFACES))]
    return "translated/scaled/mirrored", lambda: (s.translated(a[0]), s.scaled(a[2]), s.mirrored(a[0], a[1]))


# -- tolerances, analytic projection, coincident surfaces ----------------------------------
# tolerances far below the floor (1e-12 of the model size), around it, ordinary, huge and
# not numbers: each must be refused with the argument's name or answered in bounded time
TOLERANCES = [5e-324, 1e-300, 1e-20, 1e-15, 2e-12, 1e-11, 1e-6, 1e-3, 0.5, 1e3, 1e20, 1e300, math.nan, math.inf,
              -math.inf, -1e-6, 0.0]
#: the tolerances an operation runs with for real (not refused): those that bound slow work
WORKING = [1e-6, 1e-3, 0.5]


def _elementary_surfaces():
    return [
        sm.sphere(2.0, center=(1, 0, 0)),
        sm.SphericalSurface(2.0, u_range=(0.5, 2.0), v_range=(-0.3, 0.9)),
        sm.torus(3.0, 1.0, (0, 1, 0), (1, 0, 1)),
        sm.ToroidalSurface(3.0, 1.0, u_range=(1, 2.5), v_range=(4, 7)),
        sm.ConicalSurface(-0.4, 1.0, u_range=(2, 4), v_range=(-5, 1)),
        sm.CylindricalSurface(2.0, u_range=(5, 8), v_range=(0, 1)),
        sm.PlaneSurface((1, 2, 3), (0.3, 0.2, 1), u_range=(-2, 3), v_range=(-1, 2)),
        sm.plane((1, 2, 0.5), (4, 2.5, 1), (0.5, 5, 2)),  # sm.plane's skewed parallelogram: closed form too
    ]


ELEMENTARY = _elementary_surfaces()
#: a superellipsoid with creases (exponents near 2): its mesh needs 6-60x the curvature estimate
CREASED = sm.superellipsoid(1, 1, 1, 1.8, 1.8)
#: a small part for the tolerance of the tool path and the drop-cutter (a ball of 1 over it)
BOSS = bd.Box(6, 4, 2) + bd.Pos(0, 0, 1.5) * bd.Cylinder(1.2, 1)
#: a surface OCCT only approximates (cross-checked geometrically, against a tolerance)
OFFSET = sm.offset(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 0.1, 1e-4)
#: a section of BOSS through its boss: lines and a circle
SECTION = sm.section(BOSS, (0, 0, 1.5), (0, 1, 0))
_rational = sm.BSplineSurface(np.random.default_rng(11).uniform(-1, 1, (5, 5, 3)) + np.stack(np.meshgrid(
    np.arange(5.0), np.arange(5.0), [0.0], indexing="ij"), -1)[:, :, 0], (3, 3),
    weights=np.random.default_rng(12).uniform(0.5, 2.0, (5, 5)))


def _grid_points(n=8):
    x, y = np.meshgrid(np.linspace(0, 2, n), np.linspace(0, 1, n), indexing="ij")
    return np.stack([x, y, np.sin(x) * np.cos(2 * y)], -1)


def tolerance_case(rng, tmp: Path):
    k = rng.integers(24)
    tol = TOLERANCES[rng.integers(len(TOLERANCES))]
    if k >= 16:
        return _tolerance_case_more(rng, k, tol, tmp)
    if k == 0:  # 1e5 points onto an elementary surface: closed forms, never a search
        s = ELEMENTARY[rng.integers(len(ELEMENTARY))]
        pts = rng.uniform(-8, 8, (100_000, 3))
        if rng.random() < 0.3:  # on the axis, at the centre
            pts[: 1000] = 0.0
        return f"project 1e5 onto {type(s).__name__}", lambda: sm.project(pts, s)
    if k == 1:  # identical rational B-splines, any tolerance
        return "intersect identical", lambda: sm.intersect(_rational, _rational, tol)
    if k == 2:  # nearly identical: moved or one pole nudged by 1e-15 .. 1e-4
        gap = float(10.0 ** rng.uniform(-15, -4))
        b = _rational.translated((0, 0, gap)) if rng.random() < 0.5 else _nudged(_rational, gap)
        t = tol if rng.random() < 0.5 else WORKING[rng.integers(len(WORKING))]
        return "intersect nearly identical", lambda: sm.intersect(_rational, b, t)
    s = SURFACES[rng.integers(len(SURFACES))]
    if k == 3:
        return "intersect plane tol", lambda: sm.intersect(s, ((0.1, 0.2, 0.3), (0.3, 0.1, 1.0)), tol)
    if k == 4:
        return "intersect_line tol", lambda: sm.intersect_line(s, (0.1, 0.2, 0.3), (0.3, 0.1, 1.0), tolerance=tol)
    if k == 5:
        return "tessellate tol", lambda: sm.tessellate(s, tol)
    if k == 6:
        return "export_stl tol", lambda: sm.export_stl(s, tmp / "t.stl", tolerance=tol)
    if k == 7:
        return "offset tol", lambda: sm.offset(_rational, 0.2, tol)
    if k == 8:
        pts = _grid_points().reshape(-1, 3)
        return "fit tol", lambda: sm.fit(pts, tol)
    if k == 9:
        return "approximate tol", lambda: sm.approximate(_grid_points(), tolerance=tol)
    if k == 10:
        p = [sm.Line((0, y, 0), (3, y, 0)) for y in (0, 1, 2)]
        g = [sm.Line((x, 0, 0), (x, 2, 0)) for x in (0, 1.5, 3)]
        return "gordon tol", lambda: sm.gordon(p, g, tol)
    if k == 11:
        return "explicit tol", lambda: sm.explicit(lambda x, y: np.sin(x) * y, (0, 2), (0, 1), tol)
    if k == 12:
        return "superellipsoid tol", lambda: sm.superellipsoid(1.0, 1.5, 2.0, 0.5, 2.0, tolerance=tol)
    if k == 13:
        square = [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75), (0.25, 0.25)]
        return "trim tol", lambda: sm.trim(sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0)), square, tolerance=tol)
    if k == 14:
        c = [sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((0, 1, 0), (1, 1, 0)), sm.Line((0, 0, 0), (0, 1, 0)),
             sm.Line((1, 0, 0), (1, 1, 0))]
        return "coons tol", lambda: sm.coons(*c, tolerance=tol)
    sides = [sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((1, 0, 0), (1, 1, 0)), sm.Line((1, 1, 0), (0, 1, 0)),
             sm.Line((0, 1, 0), (0, 0, 0))]
    return "fill tol", lambda: sm.fill(sides, "G0", tolerance=tol)


def _tolerance_case_more(rng, k, tol, tmp: Path):
    """Issue 25's families: tool paths and drop-cutter heights, meshes of solids, the
    creased superellipsoid, and a surface against a copy of itself or a hair away."""
    if k == 16:
        return "toolpath tol", lambda: sm.toolpath(BOSS, sm.Tool("ball", 1.0), stepover=1.0, tolerance=tol)
    if k == 17:
        return "drop_cutter tol", lambda: drop_cutter(BOSS, sm.Tool("flat", 1.0), [[0.0, 0.0], [2.5, 1.0]],
                                                      tolerance=tol)
    if k == 18:
        return "export_stl solid tol", lambda: sm.export_stl(BOSS, tmp / "s.stl", tolerance=tol)
    if k == 19:
        return "tessellate creased tol", lambda: sm.tessellate(CREASED, tol)
    if k == 21:  # the pass threshold of a geometric cross-check
        return "crosscheck tol", lambda: sm.crosscheck(OFFSET, samples=4, tolerance=tol)
    if k == 22:
        return "interference tol", lambda: sm.interference(BOSS, bd.Pos(7, 0, 0) * bd.Box(1, 1, 1), tolerance=tol)
    if k == 23:  # chords of a section: 1e-12 of its size took 70 s before the floor and the point estimate
        return "export_svg tol", lambda: sm.export_svg(SECTION, tmp / "s.svg", tolerance=tol)
    s = SURFACES[rng.integers(len(SURFACES))]
    return "intersect self tol", lambda: sm.intersect(s, s, tol)


def _nudged(s, gap):
    net = np.array(s.control_points, dtype=float)
    net[2, 2, 2] += gap
    return sm.BSplineSurface(net, s.degree, s.knots, s.weights)


# -- checking -------------------------------------------------------------------------------
def _finite(value) -> bool:
    if isinstance(value, np.ndarray):
        return value.dtype.kind not in "fc" or bool(np.isfinite(value).all())
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, Surface):
        (u0, u1), (v0, v1) = value.domain
        return _finite(value.points(np.array([u0, (u0 + u1) / 2, u1]), np.array([v0, (v0 + v1) / 2, v1])))
    if isinstance(value, Curve):
        t0, t1 = value.domain
        return _finite(value.points(np.array([t0, (t0 + t1) / 2, t1])))
    if isinstance(value, sm.Mesh):
        return _finite(value.vertices)
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    if hasattr(value, "points") and isinstance(value.points, np.ndarray):  # IntersectionCurve
        return _finite(value.points)
    return True


def run_cases(make, count: int, seed: int):
    """Run ``count`` cases from ``make(rng)``; return the failures as readable lines."""
    rng = np.random.default_rng(seed)
    failures = []
    previous = signal.signal(signal.SIGALRM, _alarm)
    try:
        for i in range(count):
            name, thunk = make(rng)
            limit = SLOW_CASES.get(name, CASE_SECONDS)
            signal.setitimer(signal.ITIMER_REAL, limit)
            try:
                result = thunk()
                signal.setitimer(signal.ITIMER_REAL, 0)
                if not _finite(result):
                    failures.append(f"case {i} {name}: non-finite result without error")
            except Hang:
                failures.append(f"case {i} {name}: hang (over {limit:g} s)")
            except sm.SurfmodError as exc:
                signal.setitimer(signal.ITIMER_REAL, 0)
                if not NAMED.match(str(exc)):
                    failures.append(f"case {i} {name}: message names no argument: {str(exc)[:160]!r}")
            except Exception as exc:  # noqa: BLE001 - the raw exceptions this test hunts
                signal.setitimer(signal.ITIMER_REAL, 0)
                failures.append(f"case {i} {name}: raw {type(exc).__name__}: {str(exc)[:160]}")
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    return failures


def _report(failures, count, seed):
    return f"{len(failures)} of {count} cases broke the contract (seed {seed}):\n" + "\n".join(failures[:40])


GROUPS = [("constructors", 900), ("evaluation", 900), ("operations", 260), ("tolerances", 160)]


@pytest.mark.parametrize("group, count", GROUPS)
def test_api_fuzz(group, count, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # relative export paths land in the test's folder
    count *= SCALE
    seed = SEED + [g for g, _ in GROUPS].index(group)
    make = {
        "constructors": constructor_case,
        "evaluation": evaluation_case,
        "operations": lambda rng: operation_case(rng, tmp_path),
        "tolerances": lambda rng: tolerance_case(rng, tmp_path),
    }[group]
    failures = run_cases(make, count, seed)
    assert not failures, _report(failures, count, seed)


def test_fuzz_runs_at_least_2000_cases():
    """The CI run covers at least 2,000 API cases, the explore run at least 10,000."""
    total = sum(c for _, c in GROUPS) * SCALE
    assert total >= (10_000 if EXPLORE else 2_000)


def test_fuzz_detects_a_raw_exception():
    """The harness itself: a raw error, an unnamed message and a NaN result are caught."""

    probes = iter(range(3))

    def make(rng):
        j = next(probes)
        return "probe", [lambda: {}["x"], lambda: (_ for _ in ()).throw(sm.SurfmodError("no name here")),
                         lambda: np.array([np.nan])][j]

    failures = run_cases(make, 3, 0)
    assert [f.split(": ", 1)[1].split(" ")[0] for f in failures] == ["raw", "message", "non-finite"]


# -- damaged STEP files, in a child process -------------------------------------------------
class Driver:
    """``tests/fuzz_driver.py`` in a child process; restarted after a crash or a hang."""

    def __init__(self):
        self.proc = None

    def _start(self):
        env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parent.parent))
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("fuzz_driver.py"))],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     env=env, text=True)

    def run(self, case, seconds):
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        self.proc.stdin.write(json.dumps(case) + "\n")
        self.proc.stdin.flush()
        ready = select.select([self.proc.stdout], [], [], seconds)[0]
        line = self.proc.stdout.readline() if ready else ""
        if not line:
            # readable with nothing to read is end of file: the child died (it may not be
            # reaped yet, so poll() cannot tell a crash from a hang here)
            self.close()
            return {"outcome": f"crash (exit {self.proc.returncode})" if ready else "hang"}
        return json.loads(line)

    def close(self):
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
            self.proc.wait()
            self.proc.stdin.close()
            self.proc.stdout.close()


@pytest.fixture(scope="module")
def driver():
    d = Driver()
    yield d
    d.close()


def mutants(files, per_file: int, seed: int, folder: Path, shift: int = 0):
    """Damaged copies of ``files``: every mutation kind in turn (starting ``shift`` kinds
    on), ``per_file`` each."""
    rng = np.random.default_rng(seed)
    out = []
    for f in files:
        data = f.read_bytes()
        for j in range(per_file):
            kind = KINDS[(j + len(out) + shift) % len(KINDS)]
            path = folder / f"{f.stem[:24]}-{j:02d}-{kind}{f.suffix}"
            path.write_bytes(mutate(data, kind, rng))
            out.append(path)
    return out


SMALL = [f for f in CORPUS_FILES if f.stat().st_size < 100_000]
STEP_TIMEOUT = 5.0  # the small files read in well under a second


def check_import(driver, paths):
    failures = []
    for p in paths:
        r = driver.run({"kind": "import", "path": str(p), "timeout": STEP_TIMEOUT}, STEP_TIMEOUT + 60)
        if r["outcome"] == "ok":
            if not r["finite"]:
                failures.append(f"{p.name}: read with non-finite coordinates")
        elif r["outcome"] == "error":
            if p.name not in r["message"] or not r["message"].startswith("path: "):
                failures.append(f"{p.name}: message names neither the argument nor the file: {r['message'][:160]}")
        else:
            failures.append(f"{p.name}: {r['outcome']} {r.get('type', '')} {r.get('message', '')[:300]}")
    return failures


def test_damaged_step_files_are_refused_cleanly(driver, tmp_path):
    """A sample of mutants of four small corpus files: every kind on each (24 cases)."""
    paths = mutants(SMALL[:4], 6 * SCALE, SEED, tmp_path)
    failures = check_import(driver, paths)
    assert not failures, "\n".join(failures)


@pytest.mark.corpus
@pytest.mark.parametrize("index", range(len(JUDGED_FILES)), ids=[f.stem for f in JUDGED_FILES])
def test_damaged_step_files_whole_corpus(driver, tmp_path, index):
    # every kind on every judged file (90 cases, one test per file); each of the 222 of all
    # 37 files is a read with its own deadline, too many for CI's hour
    paths = mutants([JUDGED_FILES[index]], 6, SEED + 1 + index, tmp_path)
    failures = check_import(driver, paths)
    assert not failures, "\n".join(failures)


def _cli_args(command, path: Path, out: Path):
    return {
        "check": ["check", str(path), "--no-progress", "--jobs", "1", "--samples", "4"],
        "mesh": ["mesh", str(path), "--tolerance", "0.5", "--out", str(out / "m.stl"), "--no-progress"],
        "mass": ["mass", str(path), "--no-progress"],
        "section": ["section", str(path), "--origin", "0", "0", "1", "--normal", "0", "0", "1", "--out",
                    str(out / "s.dxf"), "--no-progress"],
        "femesh": ["femesh", str(path), "--size", "10", "--kind", "surface", "--out", str(out / "f.msh"),
                   "--no-progress"],
        "toolpath": ["toolpath", str(path), "--radius", "3", "--stepover", "5", "--step", "2", "--out",
                     str(out / "t.nc"), "--no-progress"],
    }[command]


COMMANDS = ("check", "mesh", "mass", "section", "femesh", "toolpath")


def check_cli(driver, paths, out: Path):
    failures = []
    for i, p in enumerate(paths):
        command = COMMANDS[i % len(COMMANDS)]
        r = driver.run({"kind": "cli", "argv": _cli_args(command, p, out)}, 240)
        if r["outcome"] != "done":
            failures.append(f"{command} {p.name}: {r['outcome']} {r.get('stderr', '')[-300:]}")
            continue
        # warning lines (an inside-out solid, a file that reads back changed) may come
        # before the one error line
        warning = f"surfmod {command}: warning: "
        err = "\n".join(line for line in r["stderr"].strip().splitlines() if not line.startswith(warning))
        prefix = f"surfmod {command}: error: "
        # exit 3 (written, but a promise is broken: the lines before say what) and mass's 4
        # (a disagreement with BRepGProp) are verdicts on the file, not error lines
        if r["code"] == 3 or (command == "mass" and r["code"] == 4):
            if err:
                failures.append(f"{command} {p.name}: exit {r['code']} with an error line {err[-300:]!r}")
            continue
        if r["code"] not in (0, 1, 2) or "Traceback" in err or (r["code"] and command != "check" and err.count("\n") != 0):
            failures.append(f"{command} {p.name}: exit {r['code']} with {err[-300:]!r}")
        elif r["code"] and command != "check" and not (err.startswith(prefix) and NAMED.match(err[len(prefix):])):
            failures.append(f"{command} {p.name}: the error line names no argument: {err[:200]!r}")
        elif r["code"] == 1 and command != "check" and p.name not in err:
            failures.append(f"{command} {p.name}: a damaged file's error line does not name it: {err[:200]!r}")
    return failures


def test_damaged_step_files_through_the_commands(driver, tmp_path):
    """Each of the six commands on damaged files: exit 0, 1 or 2 with one error line (3: a
    broken promise, said), never a traceback, a crash or a hang (a small sample in the
    default run)."""
    paths = mutants(SMALL[:2], 6 * SCALE, SEED + 2, tmp_path)
    failures = check_cli(driver, paths, tmp_path)
    assert not failures, "\n".join(failures)


@pytest.mark.corpus
@pytest.mark.parametrize("index", range(len(SMALL)), ids=[f.stem for f in SMALL])
def test_damaged_step_files_through_the_commands_corpus(driver, tmp_path, index):
    """Every small corpus file, damaged once for each of the six commands; the mutation
    kinds turn with the file, so over the files every (command, kind) pair comes three
    times.  One test per file, so that the corpus run's workers share them out."""
    paths = mutants([SMALL[index]], len(COMMANDS), SEED + 3 + index, tmp_path, shift=index)
    failures = check_cli(driver, paths, tmp_path)
    assert not failures, "\n".join(failures)
