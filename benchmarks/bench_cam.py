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
    scaled from 60 to 25 mm, flat r = 1, ball r = 0.8, scallop 0.008; target 60 s.

``ratio`` is OCL's time over ours (≥ 1: not slower than OCL's C++).  Beside the times:
the largest difference in height over the part's size (drop-cutter), and the share of
OCL's waterline points that lie on our loops within 1e-6 of the part's size (OCL's weave
leaves some stray points off the true contour on small loops; tests/test_waterline.py
shows them off it with OCL's own drop-cutter).

``python -m benchmarks cam``
"""

from __future__ import annotations

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
)


def job_row(out_dir: Path, path: Path, scale: float, margin: float, operations):
    """Seconds of ``sm.machine`` (verified) on the part at ``path`` scaled by ``scale`` (wall
    and this process's CPU), and of the post."""
    import build123d as bd

    t0, c0 = time.perf_counter(), time.process_time()
    part = str(path) if scale == 1.0 else bd.import_step(path).scale(scale)
    job = sm.machine(part, margin, operations())
    t1, cpu = time.perf_counter(), time.process_time() - c0
    sm.export_gcode(job, out_dir / "job.ngc", post="linuxcnc")
    t2 = time.perf_counter()
    lines = len((out_dir / "job.ngc").read_text().splitlines())
    return job, t1 - t0, cpu, t2 - t1, lines


def main() -> None:
    import tempfile

    heading("whole jobs: sm.machine (verified) and the LinuxCNC post, one core")
    table = Table(("part", 44, "<"), ("tools", 22, "<"), ("operations", 34, "<"), ("machine s", 10),
                  ("CPU s", 7), ("post s", 7), ("lines", 7), ("verified", 9), ("target", 8))
    table.header()
    for label, path, scale, margin, operations, target in JOBS:
        with tempfile.TemporaryDirectory() as tmp:
            job, t_job, cpu, t_post, lines = job_row(Path(tmp), path, scale, margin, operations)
        lo, hi = job.stock
        ops = ", ".join(f"{op.name} {len(op.motion.points)} pts" for op in job.operations)
        tools = ", ".join(f"{op.tool.kind} r={op.tool.radius:g}" for op in job.operations)
        scallop = job.operations[-1].report["scallop"]
        table.row(f"{label} ({hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} x {hi[2] - lo[2]:.3g} mm stock)",
                  f"{tools}, S {scallop:g}", ops, f"{t_job:.2f}", f"{cpu:.2f}", f"{t_post:.2f}", str(lines),
                  "yes" if job.verification.ok else "NO", f"<= {target:g} s")
    note("machine s (the first row includes loading the compiled kernels from numba's cache) covers reading "
         "the STEP file, meshing, roughing (height field, rings, every move checked), finishing (waterline "
         "contours on the steep slopes and the drop-cutter zig-zag, every move checked) and the verification "
         "(the program read back and judged against the exact part and the stock); CPU s is this process's "
         "CPU time over the same (one core: the measure on a shared machine); post s is the LinuxCNC "
         "program with its arcs.  The last two rows are issue 36's 280 mm freeform mould and its 25 mm part "
         "with a 0.8 mm ball (the corpus gear scaled from 60 mm).")
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
