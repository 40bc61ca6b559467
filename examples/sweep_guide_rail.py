"""Swept surface steered by a guide rail: the profile's frame turns so that its normal
points at the rail (OCCT: pipe shell with an auxiliary spine); with guide_scale the
section also grows and shrinks with the rail's distance (OCCT: plus a SetLaw law)."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

path = bd.Edge.make_spline([(0, 0, 0), (5, 0, 20), (20, 5, 40), (40, 0, 45)])
# the rail runs beside the path (and a little beyond its ends, so that every normal
# plane of the path meets it), swinging out in the middle
ts = [i / 7 for i in range(8)]
lift = [bd.Vector(0, 10 + 6 * t * (1 - t) * 4, 0) for t in ts]
rail_pts = [path.position_at(t) + d for t, d in zip(ts, lift)]
rail_pts = [rail_pts[0] - path.tangent_at(0) * 15] + rail_pts + [rail_pts[-1] + path.tangent_at(1) * 15]
rail = bd.Edge.make_spline(rail_pts)
start = bd.Plane(origin=path.position_at(0), z_dir=path.tangent_at(0))
profile = bd.Edge.make_three_point_arc(start.from_local_coords((-6, 0)), start.from_local_coords((0, 4)),
                                       start.from_local_coords((6, 0)))

s = sm.sweep(profile, path, guide=rail)
print("oriented by the rail:", sm.crosscheck(s, samples=16))
scaled = sm.sweep(profile, path, guide=rail, guide_scale=True)  # also sized by the rail
print("scaled to the rail:  ", sm.crosscheck(scaled, samples=16))
sm.export_step([s.face(), scaled.face().translate((50, 0, 0)), rail], OUT / "sweep_guide_rail.step")
sm.export_stl(s, OUT / "sweep_guide_rail.stl", tolerance=0.05)
