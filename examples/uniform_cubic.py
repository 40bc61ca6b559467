"""The lecture's uniform cubic B-spline surface in matrix form.

Patch (i, j) is ``[s^3 s^2 s 1] (1/6) M P_ij M^T [t^3 t^2 t 1]^T`` with the 4x4
neighbourhood ``P_ij`` of the control net; surfmod evaluates it as a general B-spline
on uniform unclamped knots and OCCT's Geom_BSplineSurface agrees point for point.
"""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

M = np.array([[-1, 3, -3, 1], [3, -6, 3, 0], [-3, 0, 3, 0], [1, 4, 1, 0]]) / 6.0

x, y = np.meshgrid(np.arange(7.0) * 10, np.arange(6.0) * 10, indexing="ij")
net = np.stack([x, y, 6 * np.cos(x / 15) * np.sin(y / 12)], axis=-1)
s = sm.BSplineSurface.uniform_cubic(net)
print("domain", s.domain, "(one unit per patch)")

# the matrix form by hand for patch (1, 2) at local (s, t) = (0.3, 0.8)
S = np.array([0.3**3, 0.3**2, 0.3, 1])
T = np.array([0.8**3, 0.8**2, 0.8, 1])
by_hand = np.einsum("a,ab,bck,dc,d->k", S, M, net[1:5, 2:6], M, T)
print("matrix form", by_hand, "surfmod", s.points(1.3, 2.8))
print(sm.crosscheck(s))

sm.export_step(s, OUT / "uniform_cubic.step")
sm.export_stl(s, OUT / "uniform_cubic.stl")
