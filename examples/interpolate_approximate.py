"""Interpolation vs approximation of a measured grid of points, each compared with
OCCT's GeomAPI_PointsToBSplineSurface on the same data."""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

rng = np.random.default_rng(7)
x, y = np.meshgrid(np.linspace(0, 50, 40), np.linspace(0, 40, 30), indexing="ij")
z = 6 * np.exp(-((x - 25) ** 2 + (y - 20) ** 2) / 150) + 0.05 * x * np.sin(y / 7)
scan = np.stack([x, y, z + rng.normal(0, 0.002, z.shape)], axis=-1)

coarse = scan[::4, ::3]
interp = sm.interpolate(coarse, method="centripetal")
_, occ_i = interp.occt_fit()
print(f"interpolate {coarse.shape[:2]}: ours {interp.max_deviation:.1e}, OCCT {occ_i:.1e} at the points")

approx = sm.approximate(scan, tolerance=0.01)
_, occ_a = approx.occt_fit()
print(f"approximate {scan.shape[:2]} -> {approx.control_points.shape[:2]} control points: "
      f"ours {approx.max_deviation:.2e}, OCCT {occ_a:.2e} (tolerance 0.01)")

sm.export_step([interp.face(), approx.translated((60, 0, 0)).face()], OUT / "interpolate_approximate.step")
sm.export_stl(approx, OUT / "interpolate_approximate.stl", tolerance=0.01)
