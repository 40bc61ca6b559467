"""Reverse engineering: the BRepMesh nodes of a fan blade face of a real part
(tests/data/step/pythonocc_Ventilator.stp), unordered and noisy like a scan,
fitted by one B-spline surface with a guaranteed deviation."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step" / "pythonocc_Ventilator.stp"

part = sm.import_step(CORPUS)
blade = max((f for f in part.faces() if f.geom_type == bd.GeomType.BSPLINE), key=lambda f: f.area)
vertices, _ = blade.tessellate(0.002, 0.1)
rng = np.random.default_rng(0)
points = np.array([tuple(v) for v in vertices])
points = points[rng.permutation(len(points))] + rng.normal(0, 0.001, (len(points), 3))  # a "scan"
print(f"{len(points)} points from a {blade.area:.1f} mm^2 blade face")

fit = sm.fit(points, tolerance=0.005)
n, m = fit.surface.control_points.shape[:2]
print(f"fit: {n}x{m} poles, max deviation {fit.max_deviation:.2e} (OCCT projection of every point), "
      f"rms {fit.rms:.2e}, converged {fit.converged}")

sm.export_step([fit.surface.face(), blade], OUT / "fit_scan.step")
np.savetxt(OUT / "fit_scan_points.xyz", points, fmt="%.6f")
