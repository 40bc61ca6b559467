"""Gallery entries beyond the lecture (issue 13): a G2 blend between two NURBS patches,
a G1 fill of a three-sided corner and a thickened patch.  ``blend_report(outdir)`` writes
the blend's continuity table and zebra picture beside them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..ops.blend import blend
from ..construct.elementary import CylindricalSurface
from ..construct.fill import fill
from ..inputs import build123d_compound
from ..construct.offset import thicken
from ..meshing.analyze import analyze
from ..nets.bspline import BSplineSurface
from ..ops.continuity import continuity
from . import entry
from .synthetic import wavy_net


def nurbs_pair():
    """Two NURBS patches facing each other across a gap of 6 units (reproducible)."""
    net_a = wavy_net(6, 5, 0.4)[:, :, :] * (0.6, 1.0, 1.0)
    w_a = np.ones((6, 5))
    w_a[2:4, 1:4] = 2.0
    a = BSplineSurface(net_a, (3, 3), weights=w_a)
    net_b = wavy_net(5, 6, 0.3) * (0.6, 1.0, 1.0) + (12.0, 0.0, 1.5)
    w_b = np.ones((5, 6))
    w_b[1:3, 2:5] = 1.5
    b = BSplineSurface(net_b, (3, 2), weights=w_b)
    return a, b


def g2_blend():
    """``(a, blend, b)`` of the gallery's G2 blend."""
    a, b = nurbs_pair()
    return a, blend(a, "u1", b, "u0", "G2"), b


@entry("g2_blend", "G2 blend between two NURBS patches", 'sm.blend(a, "u1", b, "u0", "G2")')
def _g2_blend():
    a, f, b = g2_blend()
    return build123d_compound([a.face(), f.face(), b.face()])


@entry("corner_fill", "G1 fill of a three-sided corner", "sm.fill([(x, 'v1'), (y, 'v1'), (z, 'v1')])")
def _corner_fill():
    r = 2.0
    sides = [(CylindricalSurface(r, (0, 0, 0), axis, x_dir, u_range=(0, np.pi / 2), v_range=(-6, 0)), "v1")
             for axis, x_dir in (((1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0)))]
    return build123d_compound([s.face() for s, _ in sides] + fill(sides).faces())


@entry("thicken", "thickened NURBS patch (offset + ruled walls)", "sm.thicken(s, 0.8)")
def _thicken():
    a, _ = nurbs_pair()
    return thicken(a, 0.8)


def blend_report(outdir) -> str:
    """Write ``g2_blend_zebra.png`` and ``g2_blend_continuity.txt`` into ``outdir``;
    returns the continuity table (both boundaries, OCCT's LocalAnalysis alongside)."""
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    a, f, b = g2_blend()
    table = "\n\n".join(str(continuity(x, y, occt=True)) for x, y in ((a, f), (f, b)))
    (out / "g2_blend_continuity.txt").write_text(table + "\n")
    analyze([a, f, b], "zebra", out / "g2_blend_zebra.png", light=(0.3, -0.4, 1.0), stripes=10, resolution=160,
            view=(35.0, -70.0), title="G2 blend between two NURBS patches: zebra")
    return table
