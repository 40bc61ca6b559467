"""Continuity between patches and along every edge of a part: G0 gap, G1 normal angle,
G2 jump of the normal curvature across the edge, with OCCT's LocalAnalysis alongside."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

# closed form: a plane tangent to a cylinder of radius R is G1 with a curvature jump 1/R
R = 2.0
cylinder = sm.CylindricalSurface(R, u_range=(0, 1.5), v_range=(0, 3))
plane = sm.plane((R, 0, 0), (R, 0, 3), (R, -2, 0))
print(sm.continuity(cylinder, plane, occt=True))

# two halves of a B-spline split at a simple knot are C2: every jump at round-off
halves = sm.BSplineSurface.uniform_cubic([[(i, j, (i * j) % 3) for j in range(6)] for i in range(7)]).split(u=2.0)
print(sm.continuity(*halves))

# every edge of a filleted part (faces through their p-curves)
with bd.BuildPart() as part:
    bd.Box(40, 30, 20)
    bd.fillet(part.edges().group_by(bd.Axis.Z)[-1], 5)
report = sm.continuity(part.part, samples=25, occt=True)
print(report)
sm.export_step(part.part, OUT / "continuity_part.step")
