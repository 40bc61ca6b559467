"""Hold your own evaluator against OCCT and a 40-digit reference.

Below is a NumPy de Boor evaluator written from the textbook (The NURBS Book, A3.1 on
homogeneous points), vectorized over the points; ``sm.conformance`` hands it every surface
of the stress family (crowded knots, wide and offset parameter ranges, degrees 1 to 25,
weights up to 1e4 apart, nets 1e6 from the origin...) and says, case by case, whether it
is as exact as OCCT: within max(OCCT's error, 1e-12 relative) of the reference.
"""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"


def de_boor(knots, degree, t, span, local):
    """de Boor's corner cutting of ``local[:, 0..degree]`` (the poles of each point's span)."""
    d = local.copy()
    for r in range(1, degree + 1):
        for j in range(degree, r - 1, -1):
            i = span - degree + j
            a = ((t - knots[i]) / (knots[i + degree - r + 1] - knots[i])).reshape(-1, *[1] * (d.ndim - 2))
            d[:, j] = (1 - a) * d[:, j - 1] + a * d[:, j]
    return d[:, degree]


def my_points(surface, u, v):
    """Positions ``(N, 3)`` of a B-spline, NURBS or Bézier surface at ``(u[a], v[a])``."""
    (p, q), (ku, kv) = surface.degree, surface.knots
    w = np.ones(surface.control_points.shape[:2]) if surface.weights is None else surface.weights
    h = np.concatenate([surface.control_points * w[..., None], w[..., None]], axis=-1)
    n, m = w.shape
    i = np.clip(np.searchsorted(ku, u, side="right") - 1, p, n - 1)  # the span of each point
    j = np.clip(np.searchsorted(kv, v, side="right") - 1, q, m - 1)
    local = h[(i[:, None] - p + np.arange(p + 1))[:, :, None], (j[:, None] - q + np.arange(q + 1))[:, None, :]]
    rows = de_boor(kv, q, v, j, local.transpose(0, 2, 1, 3))  # along v: (N, p + 1, 4)
    x = de_boor(ku, p, u, i, rows)                             # then along u: (N, 4)
    return x[:, :3] / x[:, 3:]


# -- the ten lines of use ----------------------------------------------------------------
table = sm.conformance(my_points, cases="stress", orders=0)
print(table.markdown())
worst = max(table.rows, key=lambda r: r.error)
print(f"worst case {worst.case!r}: own error {worst.error:.1e}, OCCT {worst.occt_error:.1e}")

# your own surfaces are cases too: a bicubic whose u-knots crowd to 1e-5 of the domain
x, y = np.meshgrid(np.linspace(0, 60, 7), np.linspace(0, 40, 5), indexing="ij")
net = np.stack([x, y, 5 * np.sin(x / 9) * np.cos(y / 7)], axis=-1)
crowded = sm.BSplineSurface(net, (3, 3), ([0, 0, 0, 0, 0.4, 0.40001, 0.40002, 1, 1, 1, 1], [0, 0, 0, 0, 0.5, 1, 1, 1, 1]))
print(sm.conformance(my_points, cases=[crowded], orders=0).summary())

# a mistake is caught: the same evaluator off by one part in 1e9
sloppy = sm.conformance(lambda s, u, v: my_points(s, u, v) * (1 + 1e-9), cases="stress", orders=0)
print("own de Boor conforms:", table.passed, "; off by 1e-9 conforms:", sloppy.passed)

sm.export_step(crowded, OUT / "conformance_own_evaluator.step")
