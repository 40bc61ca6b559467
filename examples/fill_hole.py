"""Filling holes between faces with G1 and G2, beside OCCT's BRepOffsetAPI_MakeFilling:
the three-sided corner of three fillets (G1; G2 is impossible there and is refused),
a four-sided hole in a NURBS skin and 3- and 5-sided holes in a paraboloid (G2,
curvature continuous along every side including the corners)."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm
from surfmod.construct.fill import occt_fill
from surfmod.gallery.synthetic import wavy_net

OUT = Path(__file__).resolve().parent.parent / "step_samples"
SAMPLES = 50


def worst(fill, boundary):
    """Largest gap, normal angle, curvature jump and relative jump over every side: one
    patch meets every side, patch k of n meets sides k - 1 and k (``sm.Fill``)."""
    n = len(boundary)
    pairs = [(p, nb) for p in fill for nb, _ in boundary] if len(fill) == 1 else \
        [(fill[k], boundary[j][0]) for k in range(n) for j in (k - 1, k)]
    rows = []
    for patch, nb in pairs:   # OCCT's face is projected onto the neighbour's side
        c = sm.continuity(patch, nb, samples=SAMPLES) if isinstance(patch, sm.Surface) \
            else sm.continuity(nb, patch, samples=SAMPLES)
        rows.append((c.g0, c.g1, c.g2, c.g2_relative))
    return np.max(rows, axis=0)


def report(name, rows):
    g0, g1, g2, rel = rows
    print(f"{name:44s} gap {g0:8.1e}  angle {g1:8.1e} rad  curvature jump {g2:8.1e} ({rel:.1e} relative)")


def paraboloid_hole(n):
    """n biquadratic Bezier patches of z = (x^2 + 2 y^2)/8 around an n-gon hole."""
    ang = np.pi / 2 + 2 * np.pi * np.arange(n) / n + 0.3
    ring = np.stack([np.cos(ang), np.sin(ang)], 1)
    t = np.array([0.0, 0.5, 1.0])
    inv = np.linalg.inv(np.stack([(1 - t) ** 2, 2 * t * (1 - t), t**2], 1))
    sides = []
    for k in range(n):
        a, b, c, d = ring[k], ring[(k + 1) % n], 2 * ring[k], 2 * ring[(k + 1) % n]
        s, w = np.meshgrid(t, t, indexing="ij")
        xy = ((1 - s) * (1 - w))[..., None] * a + (s * (1 - w))[..., None] * b + ((1 - s) * w)[..., None] * c \
            + (s * w)[..., None] * d
        pts = np.concatenate([xy, ((xy[..., 0] ** 2 + 2 * xy[..., 1] ** 2) / 8)[..., None]], axis=-1)
        sides.append((sm.BezierSurface(np.einsum("ia,jb,abk->ijk", inv, inv, pts)), "v0"))
    return sides


# -- three fillets at a box corner: G1; G2 would need equal curvatures at the corners ---------------
r = 2.0
fillets = [(sm.CylindricalSurface(r, (0, 0, 0), axis, x_dir, u_range=(0, np.pi / 2), v_range=(-6, 0)), "v1")
           for axis, x_dir in (((1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0)))]
corner = sm.fill(fillets)
report("3-sided fillet corner, sm.fill G1", worst(corner, fillets))
try:
    sm.fill(fillets, "G2")
except sm.SurfmodError as exc:
    print("  sm.fill G2 refused:", exc)
relaxed = sm.fill(fillets, "G2", allow_singular_corners=True)
print("  corner mismatches (relative curvature):", [round(c.curvature, 6) for c in relaxed.corners])
report("  G2, allow_singular_corners (corner samples)", worst(relaxed, fillets))
report("3-sided fillet corner, MakeFilling G1", worst([occt_fill(fillets)], fillets))
sm.export_step(bd.Compound([s.face() for s, _ in fillets] + corner.faces()), OUT / "fill_corner.step")

# -- a four-sided hole in a NURBS skin -------------------------------------------------------------
skin = sm.BSplineSurface(wavy_net(7, 7, 0.4))
pieces = {(i, j): skin.segment(u, v) for i, u in enumerate(((0, .35), (.35, .65), (.65, 1)))
          for j, v in enumerate(((0, .35), (.35, .65), (.65, 1)))}
hole = [(pieces[1, 0], "v1"), (pieces[2, 1], "u0"), (pieces[1, 2], "v0"), (pieces[0, 1], "u1")]
ours_g1, ours_g2 = sm.fill(hole), sm.fill(hole, "G2")
report("4-sided hole in a NURBS skin, sm.fill G1", worst(ours_g1, hole))
report("4-sided hole in a NURBS skin, sm.fill G2", worst(ours_g2, hole))
report("4-sided hole in a NURBS skin, MakeFilling G1", worst([occt_fill(hole)], hole))
sm.export_step(bd.Compound([p.face() for p, _ in hole] + ours_g2.faces()), OUT / "fill_hole.step")

# -- 3- and 5-sided holes in a paraboloid ------------------------------------------------------------
for n in (3, 5):
    sides = paraboloid_hole(n)
    g2 = sm.fill(sides, "G2")
    report(f"{n}-sided hole in a paraboloid, sm.fill G2", worst(g2, sides))
    report(f"{n}-sided hole in a paraboloid, MakeFilling G1", worst([occt_fill(sides)], sides))
    sm.export_step(bd.Compound([p.face() for p, _ in sides] + g2.faces()), OUT / f"fill_paraboloid_{n}.step")
