"""Lofted surfaces through cross sections (smooth and ruled), e.g. a hull or a duct,
compared with OCCT's BRepOffsetAPI_ThruSections."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

# a duct: circle -> ellipse -> circle, as build123d edges
sections = [
    bd.Edge.make_circle(10),
    bd.Edge.make_ellipse(16, 8, bd.Plane.XY.offset(25)),
    bd.Edge.make_circle(6, bd.Plane.XY.offset(50)),
]
smooth = sm.loft(sections)
ruled = sm.loft(sections, ruled=True)
print("smooth", sm.crosscheck(smooth, samples=16))
print("ruled ", sm.crosscheck(ruled, samples=16), "| to OCCT's ruled shell:", f"{ruled.occt_deviation(16):.2e}")

sm.export_step([smooth.face(), ruled.face().translate((40, 0, 0))], OUT / "loft_sections.step")
sm.export_stl(smooth, OUT / "loft_sections.stl", tolerance=0.05)
