"""CAM kernels beside OpenCAMLib: waterline contours and drop-cutter heights on corpus
parts, the same triangles on both sides (BRepMesh at 0.05 mm), one core each
(``NUMBA_NUM_THREADS``/``OMP_NUM_THREADS`` as the caller sets them; OCL is given
``setThreads(1)``).

* waterline: ``surfmod.cam.waterline.waterline`` at ``LEVELS`` tip heights spread over
  the part, fiber sampling ``SAMPLING`` and the default tolerance (1e-6 of the part's
  size: chords refined to the exact contour), against OCL's ``Waterline`` at the same
  sampling (its points exact on the fibers, joined by straight lines between them);
* drop-cutter: ``surfmod.cam.drop_cutter.drop`` (grid build included) at ``POINTS``
  random (x, y) over the part, against OCL's ``BatchDropCutter``.

* whole jobs (:data:`JOBS`): ``sm.machine`` from 2 mm of stock, verification included,
  plus the LinuxCNC post, seconds on one core, STEP reading included (OCL has no job to
  compare with):

  - ``step_samples/cam_part.step`` (an 80 x 60 x 25 mm NURBS mould, the part of
    examples/cam_machining.py), roughing with a flat r = 5 (stepdown 5, allowance 0.5)
    and finishing with a ball r = 3 (scallop 0.15); target 60 s;
  - the same part scaled to 100 mm (issue 36's freeform part: tools 3-5 % of its size,
    the scallop 1 % of the ball radius): flat r = 4, ball r = 3, scallop 0.03, flutes 40 mm
    long (the part is 32 mm tall); target 60 s;
  - issue 36's 280 mm freeform mould (the corpus' ``occt_cornetta.stp``, 280 x 160 x 62 mm,
    74 B-spline faces): flat r = 12, ball r = 9, scallop 0.09, flutes 80 mm; target 90 s;
  - issue 36's 25 mm part with a 0.8 mm ball: the corpus gear ``f360grbl_gear.step``
    scaled from 60 to 25 mm, flat r = 1, ball r = 0.8, scallop 0.008; target 60 s;
  - issue 36's 1000 x 1000 x 400 mm part (:func:`big_part`, built here: a plate with a
    freeform top, three pockets 140-260 mm deep with 40 mm corners, bosses in two of them
    and one on the top): flat r = 25 and ball r = 16 (50 and 32 mm tools) on 420 mm
    reach (flutes 4 radii, a neck 1 mm narrower above them); target 600 s and 4 GB.

Each job runs in a child process forked for it, so that its peak memory (``peak MB``, the
child's ``ru_maxrss``, the parent's pages at the fork included) is its own.

``ratio`` is OCL's time over ours (≥ 1: not slower than OCL's C++).  Beside the times:
the largest difference in height over the part's size (drop-cutter), and the share of
OCL's waterline points that lie on our loops within 1e-6 of the part's size (OCL's weave
leaves some stray points off the true contour on small loops; tests/test_waterline.py
shows them off it with OCL's own drop-cutter).

``python -m benchmarks cam``
"""

from __future__ import annotations

import json
import os
import resource
import time
from pathlib import Path

import numpy as np

import surfmod as sm
from surfmod.cam.cutters import CUTTERS
from surfmod.cam.drop_cutter import TriangleGrid, drop
from surfmod.cam.waterline import waterline
from surfmod.errors import SurfmodError
from surfmod.inputs import to_shape
from surfmod.cam.drop_cutter import part_triangles

from .tables import Table, captured_stdout, heading, note

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"
JOB_PART = Path(__file__).resolve().parent.parent / "step_samples" / "cam_part.step"
PARTS = ("trimesh_featuretype.STEP", "pythonocc_face_recognition_sample_part.stp", "trimesh_box_sides.STEP")
TOOLS = (("ball", 3.0, 0.0), ("flat", 3.0, 0.0), ("bull", 3.0, 1.0))
LEVELS = 3
SAMPLING = 0.5
POINTS = 20_000
DEFLECTION = 0.05


def _ocl_surface(ocl, tri):
    surf = ocl.STLSurf()
    for t in tri:
        surf.addTriangle(ocl.Triangle(*(ocl.Point(float(x), float(y), float(z)) for x, y, z in t)))
    return surf


def _ocl_cutter(ocl, kind, R, r):
    if kind == "ball":
        return ocl.BallCutter(2 * R, 1000.0)
    if kind == "flat":
        return ocl.CylCutter(2 * R, 1000.0)
    return ocl.BullCutter(2 * R, r, 1000.0)


def _polyline_distance(points, loops):
    a = np.vstack([lp[:, :2] for lp in loops])
    b = np.vstack([np.roll(lp[:, :2], -1, axis=0) for lp in loops])
    out = np.empty(len(points))
    for k0 in range(0, len(points), 200):
        p = points[k0:k0 + 200, None, :2]
        ab = b - a
        t = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
        out[k0:k0 + 200] = np.linalg.norm(p - (a + t[..., None] * ab), axis=-1).min(axis=1)
    return out


def rows():
    import opencamlib as ocl

    for name in PARTS:
        tri, _ = part_triangles(to_shape(CORPUS / name), DEFLECTION)
        pts = tri.reshape(-1, 3)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        size = float((hi - lo).max())
        surf = _ocl_surface(ocl, tri)
        levels = lo[2] + (hi[2] - lo[2]) * (np.arange(LEVELS) + 0.5) / LEVELS
        xy = lo[:2] + np.random.default_rng(7).random((POINTS, 2)) * (hi - lo)[:2]
        for kind, R, r in TOOLS:
            tool = CUTTERS[kind](R, r)
            cutter = _ocl_cutter(ocl, kind, R, r)
            # waterline
            t0 = time.perf_counter()
            ours = waterline(tri, tool, levels, sampling=SAMPLING)
            t_ours = time.perf_counter() - t0
            t_ocl, on, total = 0.0, 0, 0
            for z, loops in zip(levels, ours):
                wl = ocl.Waterline()
                wl.setSTL(surf)
                wl.setCutter(cutter)
                wl.setZ(float(z))
                wl.setSampling(SAMPLING)
                wl.setThreads(1)
                with captured_stdout():  # OpenCAMLib's facetPush() diagnostics: not the table's
                    t0 = time.perf_counter()
                    wl.run()
                    t_ocl += time.perf_counter() - t0
                    theirs = [np.array([[p.x, p.y] for p in loop]) for loop in wl.getLoops()]
                    del wl
                if theirs and loops:
                    d = _polyline_distance(np.vstack(theirs), loops)
                    on += int(np.sum(d <= 1e-6 * size))
                    total += len(d)
            n_pts = sum(len(lp) for loops in ours for lp in loops)
            share = f"{on / total:.2%} on ours" if total else "no loops"
            yield name, kind, "waterline", f"{LEVELS} levels, {n_pts} pts", t_ours, t_ocl, share
            # drop-cutter
            try:
                t0 = time.perf_counter()
                z_ours = drop(TriangleGrid(tri, R), tool, xy)
                t_ours = time.perf_counter() - t0
            except (SurfmodError, TypeError):  # a kind this surfmod.cam does not drop yet
                yield name, kind, "drop-cutter", "not in surfmod.cam yet", float("nan"), float("nan"), ""
                continue
            bdc = ocl.BatchDropCutter()
            bdc.setSTL(surf)
            bdc.setCutter(cutter)
            bdc.setThreads(1)
            floor = float(lo[2]) - 100.0
            for x, y in xy:
                bdc.appendPoint(ocl.CLPoint(float(x), float(y), floor))
            with captured_stdout():  # OpenCAMLib's facetPush() diagnostics: not the table's
                t0 = time.perf_counter()
                bdc.run()
                t_ocl = time.perf_counter() - t0
            z_ocl = np.array([p.z for p in bdc.getCLPoints()])
            hit = np.isfinite(z_ours)
            diff = float(np.abs(z_ours[hit] - z_ocl[hit]).max(initial=0.0)) / size
            yield name, kind, "drop-cutter", f"{POINTS} points", t_ours, t_ocl, f"{diff:.1e}"


#: whole-job rows: (label, part, scale, stock margin, operations, target s)
JOBS = (
    ("cam_part.step", JOB_PART, 1.0, 2.0,
     lambda: [sm.Rough(sm.Tool("flat", 5.0), stepdown=5.0, allowance=0.5),
              sm.Finish(sm.Tool("ball", 3.0), scallop=0.15)], 60.0),
    ("cam_part.step x 1.25", JOB_PART, 1.25, 2.0,
     lambda: [sm.Rough(sm.Tool("flat", 4.0, flute_length=40.0), allowance=0.5),
              sm.Finish(sm.Tool("ball", 3.0, flute_length=40.0), scallop=0.03)], 60.0),
    ("occt_cornetta.stp", CORPUS / "occt_cornetta.stp", 1.0, 2.0,
     lambda: [sm.Rough(sm.Tool("flat", 12.0, flute_length=80.0)),
              sm.Finish(sm.Tool("ball", 9.0, flute_length=80.0), scallop=0.09)], 90.0),
    # the gear is 60 mm across: scaled to the 25 mm
    ("f360grbl_gear.step x 25/60", CORPUS / "f360grbl_gear.step", 25.0 / 60.0, 1.0,
     lambda: [sm.Rough(sm.Tool("flat", 1.0)), sm.Finish(sm.Tool("ball", 0.8), scallop=0.008)], 60.0),
    ("1000 mm plate (big_part)", "big_part", 1.0, 2.0,
     lambda: [sm.Rough(_long("flat", 25.0)), sm.Finish(_long("ball", 16.0), scallop=BIG_SCALLOP)], 600.0),
)
#: the finishing scallop on the 1000 mm plate
BIG_SCALLOP = 0.5
#: the tools' reach on the 1000 mm plate: from the table (z 0) past the stock's top (z 402)
BIG_REACH = 420.0


def _long(kind: str, radius: float) -> sm.Tool:
    """A long-reach tool, ``BIG_REACH`` below its holder: flutes four radii long, then a
    neck 1 mm narrower than the end (a shank as wide would rub the roughing's allowance on
    a wall taller than the flutes)."""
    return sm.Tool(kind, radius, flute_length=4 * radius, shank_radius=radius - 1.0,
                   shank_length=BIG_REACH - 4 * radius)


def big_part():
    """Issue 36's 1000 x 1000 x 400 mm part: a 1000 mm square plate whose top is a
    B-spline wave (330 +- 25 mm), three pockets with 40 mm corners down to z 70, 130 and
    190, a boss of r 60 and one of r 50 standing from two pocket floors to z 400, and a
    boss of r 70 on the top."""
    import build123d as bd

    xs = np.linspace(-500.0, 500.0, 9)
    top = bd.Face.make_surface_from_array_of_points(
        [[bd.Vector(x, y, 330.0 + 25.0 * np.sin(x / 160.0) * np.cos(y / 210.0)) for y in xs] for x in xs])
    part = bd.Solid.extrude(top, bd.Vector(0, 0, -400)) & bd.Pos(0, 0, 150) * bd.Box(1000, 1000, 300)
    up = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
    for x, y, w, d, floor, boss in ((-250, -250, 300, 260, 130, 60), (250, -200, 280, 340, 70, 50),
                                    (-200, 250, 340, 260, 190, 0)):
        pocket = bd.Pos(x, y, (floor + 400) / 2) * bd.Box(w, d, 400 - floor)
        part -= bd.fillet(pocket.edges().filter_by(bd.Axis.Z), 40)
        if boss:
            part += bd.Pos(x, y, floor) * bd.Cylinder(boss, 400 - floor, align=up)
    return part + bd.Pos(250, 250, 300) * bd.Cylinder(70, 100, align=up)


def job_row(out_dir: Path, path: Path, scale: float, margin: float, operations):
    """Seconds of ``sm.machine`` (verified) on the part at ``path`` scaled by ``scale`` (wall
    and this process's CPU), and of the post."""
    import build123d as bd

    if path == "big_part":
        path = out_dir / "big_part.step"
        bd.export_step(big_part(), path)
    t0, c0 = time.perf_counter(), time.process_time()
    part = str(path) if scale == 1.0 else bd.import_step(path).scale(scale)
    job = sm.machine(part, margin, operations())
    t1, cpu = time.perf_counter(), time.process_time() - c0
    sm.export_gcode(job, out_dir / "job.ngc", post="linuxcnc")
    t2 = time.perf_counter()
    lines = len((out_dir / "job.ngc").read_text().splitlines())
    return job, t1 - t0, cpu, t2 - t1, lines


def job_cells(k: int) -> list[str]:
    """The table's cells of the job ``JOBS[k]``."""
    import tempfile

    label, path, scale, margin, operations, target = JOBS[k]
    with tempfile.TemporaryDirectory() as tmp:
        job, t_job, cpu, t_post, lines = job_row(Path(tmp), path, scale, margin, operations)
    lo, hi = job.stock
    ops = ", ".join(f"{op.name} {len(op.motion.points)} pts" for op in job.operations)
    tools = ", ".join(f"{op.tool.kind} r={op.tool.radius:g}" for op in job.operations)
    scallop = job.operations[-1].report["scallop"]
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    return [f"{label} ({hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} x {hi[2] - lo[2]:.3g} mm stock)",
            f"{tools}, S {scallop:g}", ops, f"{t_job:.2f}", f"{cpu:.2f}", f"{peak:.0f}", f"{t_post:.2f}", str(lines),
            "yes" if job.verification.ok else "NO", f"<= {target:g} s"]


def in_child(fn, *args):
    """``fn(*args)`` (JSON-able) computed in a forked child: its peak memory is its own."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: answer through the pipe, never return into the caller's code
        os.close(read)
        code = 1
        try:
            with os.fdopen(write, "w") as out:
                json.dump(fn(*args), out)
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    with os.fdopen(read) as got:
        text = got.read()
    _, status = os.waitpid(pid, 0)
    if status != 0:
        raise RuntimeError(f"{fn.__name__}{args}: the child failed (status {status})")
    return json.loads(text)


def main() -> None:
    heading("whole jobs: sm.machine (verified) and the LinuxCNC post, one core")
    table = Table(("part", 44, "<"), ("tools", 22, "<"), ("operations", 34, "<"), ("machine s", 10),
                  ("CPU s", 7), ("peak MB", 8), ("post s", 7), ("lines", 7), ("verified", 9), ("target", 8))
    table.header()
    for k in range(len(JOBS)):
        table.row(*in_child(job_cells, k))
    note("machine s (every row includes loading the compiled kernels from numba's cache: each job runs in a "
         "child of its own) covers reading "
         "the STEP file, meshing, roughing (height field, rings, every move checked), finishing (waterline "
         "contours on the steep slopes and the drop-cutter zig-zag, every move checked) and the verification "
         "(the program read back and judged against the exact part and the stock); CPU s is this process's "
         "CPU time over the same (one core: the measure on a shared machine); post s is the LinuxCNC "
         "program with its arcs; peak MB the job's child process at its highest (ru_maxrss).  The last three "
         "rows are issue 36's 280 mm freeform mould, its 25 mm part with a 0.8 mm ball (the corpus gear scaled "
         "from 60 mm) and its 1000 x 1000 x 400 mm part (tools 50 and 32 mm on 420 mm of reach).")
    heading("waterline and drop-cutter beside OpenCAMLib (one core each side)")
    table = Table(("part", 40, "<"), ("tool", 5), ("kernel", 11), ("size", 24), ("ours s", 8), ("OCL s", 8),
                  ("ratio", 6), ("agreement", 18))
    table.header()
    for name, kind, op, what, t_ours, t_ocl, diff in rows():
        ratio = t_ocl / t_ours if t_ours == t_ours else float("nan")
        table.row(name, kind, op, what, f"{t_ours:.3f}", f"{t_ocl:.3f}", f"{ratio:.2f}", diff)
    note(f"R = 3 mm (bull r = 1 mm), BRepMesh deflection {DEFLECTION} mm, waterline sampling {SAMPLING} mm; "
         "ratio = OCL time / ours (>= 1: surfmod not slower)")


if __name__ == "__main__":
    main()
