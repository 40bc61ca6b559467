"""G2 blend between two NURBS patches, beside OCCT's nearest construct, build123d style.

sm.blend builds an exact B-spline (quintic across) that meets both patches with
curvature continuity; OCCT's BRepOffsetAPI_MakeFilling on the same four boundary edges
reaches only approximate G1 and refuses G2 as a constraint order.  Writes the three faces
as STEP, the continuity tables and a zebra picture to step_samples/.
"""

from pathlib import Path

import build123d as bd

import surfmod as sm
from surfmod.ops.blend import occt_blend
from surfmod.gallery.beyond import blend_report, nurbs_pair

OUT = Path(__file__).resolve().parent.parent / "step_samples"

a, b = nurbs_pair()
g2 = sm.blend(a, "u1", b, "u0", "G2")
print(f"blend: degree {g2.degree}, {g2.control_points.shape[0]} x {g2.control_points.shape[1]} poles, "
      f"rational={g2.rational}")
print(blend_report(OUT))          # continuity tables (ours and LocalAnalysis) + zebra PNG

filling, face_a, face_b = occt_blend(a, "u1", b, "u0", g2, "G1")
for name, x, y in (("a | OCCT filling", a, filling), ("OCCT filling | b", b, filling)):
    c = sm.continuity(x, y, occt=True)
    print(f"{name}: gap {c.g0:.2e}, normal angle {c.g1:.2e} rad, curvature jump {c.g2:.2e}")
try:
    occt_blend(a, "u1", b, "u0", g2, "G2")
except sm.KernelError as exc:
    print(f"OCCT with G2 constraints: {exc}")

sm.export_step(bd.Compound([a.face(), g2.face(), b.face()]), OUT / "g2_blend.step")
