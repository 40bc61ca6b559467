"""Subdivision surfaces: a cube cage becomes a smooth CAD solid (Catmull–Clark limit).

The lecture's "coarse mesh & subdivision rule -> smooth surface as the limit of
refinements": eight points and six quads are refined twice (isolating the eight
valence-3 corners), every regular face becomes its exact bicubic uniform B-spline patch,
the 24 faces at the corners become bicubic Bézier patches whose gap and normal error are
measured, and the 96 patches are sewn into a solid written to STEP.  ``adaptive`` levels
refine only the corner patches, shrinking the approximation error at little cost.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

cage_vertices = 20.0 * np.array(
    [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)], dtype=float
)
cage_quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]

# the refinement itself (a polygon mesh), for comparison
mesh = sm.catmull_clark(cage_vertices, cage_quads, levels=3)
print(f"Catmull-Clark, 3 levels: {len(mesh.vertices)} vertices, {len(mesh.faces)} quads, "
      f"watertight: {mesh.to_trimesh().is_watertight}")

# the limit surface as CAD geometry
limit = sm.limit_surface(cage_vertices, cage_quads, levels=2)
e = limit.errors
print(limit)
print(f"  gap between patches     {e['max_gap']:.2e}")
print(f"  normal jump across edges {e['max_normal_angle_deg']:.3f} deg "
      f"(exact B-spline edges: {e['max_normal_angle_regular_deg']:.1e} deg)")
print(f"  distance to exact limit {e['max_limit_deviation']:.4f} "
      f"({100 * e['max_limit_deviation_rel']:.3f} % of the size), normal {e['max_limit_normal_deg']:.3f} deg")

# feature-adaptive refinement: only the patches at the eight corners are refined further
print("adaptive  patches  normal jump [deg]  distance to limit [% of size]")
for adaptive in (0, 1, 2, 3):
    e = sm.limit_surface(cage_vertices, cage_quads, levels=2, adaptive=adaptive).errors
    print(f"{adaptive:8d}  {e['patches']:7d}  {e['max_normal_angle_deg']:17.3f}  {100 * e['max_limit_deviation_rel']:13.4f}")

solid = limit.solid()
print(f"solid: {len(solid.faces())} faces, volume {solid.volume:.3f}, valid {solid.is_valid}")

# it is an ordinary build123d solid (bounding box, placement, algebra mode)
bb = solid.bounding_box()
print(f"bounding box {bb.min} .. {bb.max}")
moved = bd.Pos(0, 0, 5) * solid
OUT.mkdir(exist_ok=True)
sm.export_step(moved, OUT / "subdivision_cube.step")
sm.export_stl(mesh, OUT / "subdivision_cube_cc3.stl")
print("wrote", OUT / "subdivision_cube.step")
