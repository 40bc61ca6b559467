"""Mass properties of a solid bounded by NURBS faces and of a STEP part.

Gauss quadrature of the divergence theorem on surfmod's NumPy evaluator, against
OCCT's BRepGProp at a tight tolerance (1e-9) and at its default tolerance.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

# a 60 x 40 block whose top is a bicubic B-spline (x, y linear in u, v: Greville abscissae)
n, p = 6, 3
k = np.concatenate([[0] * p, np.linspace(0, 1, n - p + 1), [1] * p])
g = np.array([k[i + 1:i + p + 1].mean() for i in range(n)])
z = 15 + 5 * np.sin(3 * g[:, None]) * np.cos(2 * g[None, :])
net = np.stack(np.broadcast_arrays(60 * g[:, None], 40 * g[None, :], z), -1)
top = sm.BSplineSurface(net, (p, p), (k, k))
bot = net.copy()
bot[..., 2] = 0
sides = [sm.BSplineSurface(np.stack([a, b]), (1, p), ([0, 0, 1, 1], k))
         for a, b in [(net[0], bot[0]), (net[-1], bot[-1]), (net[:, 0], bot[:, 0]), (net[:, -1], bot[:, -1])]]
block = sm.make_solid([top, sm.plane((0, 0, 0), (60, 0, 0), (0, 40, 0)), *sides])

w = (k[p + 1:] - k[:-p - 1]) / (p + 1)
exact = 60 * 40 * np.einsum("i,j,ij", w, w, z)
r = sm.mass_properties(block, density=7.85e-3)  # steel, g/mm^3
print(r)
o = sm.mass_properties(block, method="occt", eps=1e-9)
print(f"BRepGProp eps=1e-9 volume error vs closed form {abs(o.volume - exact) / exact:.1e}")
print(f"NumPy quadrature volume error vs closed form {abs(r.volume - exact) / exact:.1e}")

# a filleted, drilled STEP part: trimmed faces go through Green's theorem in (u, v)
part = bd.fillet(bd.Box(50, 30, 10).edges().filter_by(bd.Axis.Z), radius=5) - bd.Cylinder(6, 20)
sm.export_step([block, part], OUT / "mass_properties.step")
sm.export_step(part, OUT / "mass_part.step")
rp = sm.mass_properties(OUT / "mass_part.step")
op = sm.mass_properties(OUT / "mass_part.step", method="occt")
print(f"STEP part: volume {rp.volume:.9f} (BRepGProp {op.volume:.9f}), faces {rp.faces}")
sm.export_stl(block, OUT / "mass_properties.stl", tolerance=0.01)
