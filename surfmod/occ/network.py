"""OCCT's curve-network surfaces, for comparison with surfmod's own constructs:
``GeomFill_BSplineCurves`` (Coons style) and build123d's Gordon surface
(``Face.make_gordon_surface``), plus distances from curves to a surface."""

from __future__ import annotations

import numpy as np

from ..errors import KernelError
from .guard import kernel
from OCP.GeomFill import GeomFill_BSplineCurves, GeomFill_FillingStyle
from .sample import distances_to_surface


def bspline_curves_fill(c1, c2, c3, c4, style: str = "coons"):
    """``GeomFill_BSplineCurves(c1, c2, c3, c4, style)``: four ``Geom_BSplineCurve``
    handles forming a closed loop (OCCT arranges and orients them); returns the
    ``Geom_BSplineSurface``."""
    styles = {
        "coons": GeomFill_FillingStyle.GeomFill_CoonsStyle,
        "stretch": GeomFill_FillingStyle.GeomFill_StretchStyle,
        "curved": GeomFill_FillingStyle.GeomFill_CurvedStyle,
    }
    with kernel("GeomFill_BSplineCurves"):
        fill = GeomFill_BSplineCurves(c1, c2, c3, c4, styles[style])
        return fill.Surface()


def reversed_curve(curve):
    """OCCT's reversed copy of a ``Geom_BSplineCurve``."""
    with kernel("Geom_BSplineCurve.Reversed"):
        return curve.Reversed()


def gordon_face(profiles, guides, tolerance: float):
    """build123d's ``Face.make_gordon_surface`` (the ``ocp_gordon`` package) on the
    given build123d edges; raises ``KernelError`` when it fails."""
    import build123d as bd

    try:
        return bd.Face.make_gordon_surface(list(profiles), list(guides), tolerance=tolerance)
    except Exception as exc:  # ocp_gordon raises plain Python errors as well as OCCT ones
        raise KernelError(f"Face.make_gordon_surface: failed ({type(exc).__name__}: {exc})") from exc


def curve_to_surface_distances(surf, bounds, curve, samples: int) -> np.ndarray:
    """Distances from ``samples`` points along a ``Geom_Curve`` (uniform in its
    parameter) to a bounded ``Geom_Surface``, by OCCT point projection."""
    with kernel("Geom_Curve.Value"):
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        pts = np.array([curve.Value(float(t)).Coord() for t in np.linspace(t0, t1, samples)])
    return distances_to_surface(surf, pts, bounds)
