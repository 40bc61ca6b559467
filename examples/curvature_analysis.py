"""Zebra stripes, isophotes, curvature maps and combs, headless, for a surface and a part."""

from pathlib import Path

import build123d as bd

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net

OUT = Path(__file__).resolve().parent.parent / "step_samples"

patch = sm.BSplineSurface(wavy_net(7, 6))
for kind in ("zebra", "isophote", "gaussian", "mean", "max_abs", "comb"):
    result = sm.analyze(patch, kind, OUT / f"analysis_{kind}.png", light=(0.2, -0.3, 1.0))
    print(f"{kind:9s} range [{result.values.min():+.4f}, {result.values.max():+.4f}]")
f = result.fairness[0]
print(f"fairness: area {f.area:.3f}, bending {f.bending:.4f}, variation of H {f.variation:.4f}")

with bd.BuildPart() as part:
    bd.Box(40, 30, 20)
    bd.fillet(part.edges(), 4)
sm.export_step(part.part, OUT / "analysis_part.step")
print(sm.analyze(part.part, "zebra", OUT / "analysis_part_zebra.png"))
