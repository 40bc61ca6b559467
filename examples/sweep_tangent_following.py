"""Swept surface following the path tangent: a profile carried along a helix by the
Frenet frame and by the corrected (rotation-minimizing) frame, build123d style.

The helix and the elliptic profile are plain build123d edges; surfmod sweeps them with
its NumPy evaluator and OCCT's BRepOffsetAPI_MakePipeShell, and reports how far apart
the two are.
"""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

helix = bd.Edge.make_helix(pitch=20, height=40, radius=15)
start = bd.Plane(origin=helix.position_at(0), z_dir=helix.tangent_at(0))
profile = bd.Edge.make_ellipse(4.0, 1.5, start)  # asymmetric: the frame's spin shows

frenet = sm.sweep(profile, helix, mode="frenet")
rmf = sm.sweep(profile, helix, mode="corrected_frenet")
for name, s in (("Frenet", frenet), ("rotation-minimizing", rmf)):
    print(f"{name:>20}: {sm.crosscheck(s, samples=16)}")

sm.export_step([frenet.face(), rmf.face().translate((50, 0, 0))], OUT / "sweep_tangent_following.step")
sm.export_stl(frenet, OUT / "sweep_tangent_following.stl", tolerance=0.05)
