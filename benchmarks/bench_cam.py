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
from types import SimpleNamespace

import numpy as np

from surfmod.cam.drop_cutter import TriangleGrid, drop
from surfmod.cam.waterline import waterline
from surfmod.errors import SurfmodError
from surfmod.inputs import to_shape
from surfmod.occ.triangulation import part_triangles

from .tables import Table, note

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"
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
            tool = SimpleNamespace(kind=kind, radius=R, corner_radius=r)
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
                t0 = time.perf_counter()
                wl.run()
                t_ocl += time.perf_counter() - t0
                theirs = [np.array([[p.x, p.y] for p in loop]) for loop in wl.getLoops()]
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
                z_ours = drop(TriangleGrid(tri, R), kind, xy, corner=r)
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
            t0 = time.perf_counter()
            bdc.run()
            t_ocl = time.perf_counter() - t0
            z_ocl = np.array([p.z for p in bdc.getCLPoints()])
            hit = np.isfinite(z_ours)
            diff = float(np.abs(z_ours[hit] - z_ocl[hit]).max(initial=0.0)) / size
            yield name, kind, "drop-cutter", f"{POINTS} points", t_ours, t_ocl, f"{diff:.1e}"


def main() -> None:
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
