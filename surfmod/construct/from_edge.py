"""Read OCCT / build123d edges and wires back into surfmod curves (``from_edge``,
``as_curve`` wherever a constructor takes a curve).

Faces are read by :mod:`surfmod.readback` (``sm.from_face``), the one reader of faces.
"""

from __future__ import annotations

from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve


def from_edge(edge):
    """A surfmod curve for a build123d ``Edge``/``Wire`` or OCP edge (exact B-spline form
    of the edge's 3-D curve over its parameter range).

    >>> import surfmod as sm, build123d as bd
    >>> c = sm.from_edge(bd.Edge.make_line((0, 0, 0), (3, 4, 0)))
    >>> c.points(c.domain[1])
    array([3., 4., 0.])
    """
    from ..occ.geom import read_bspline_curve
    from ..occ.topo import shape_bspline

    data = read_bspline_curve(shape_bspline(edge))
    return BSplineCurve(data["points"], data["degree"], data["knots"], data["weights"])


def as_curve(value, name: str):
    """Accept a surfmod curve or a build123d Edge/Wire wherever a curve is taken."""
    if isinstance(value, Curve):
        return value
    if hasattr(value, "wrapped") or type(value).__name__.startswith("TopoDS"):
        try:
            return from_edge(value)
        except SurfmodError as exc:
            raise SurfmodError(f"{name}: {exc}") from None
    raise SurfmodError(f"{name}: expected a surfmod curve or a build123d Edge/Wire, got {type(value).__name__}")


def as_curves(value, name: str, purpose: str, minimum: int = 2) -> list:
    """A list of at least ``minimum`` curves (surfmod curves or build123d edges/wires),
    each through :func:`as_curve`; ``purpose`` completes the message ("a loft needs...").

    >>> import surfmod as sm
    >>> as_curves([sm.Line((0, 0, 0), (1, 0, 0))], "sections", "a loft")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: sections: a loft needs at least 2, got 1
    """
    try:
        items = list(value)
    except TypeError:
        raise SurfmodError(f"{name}: expected a list of curves, got {type(value).__name__}") from None
    if len(items) < minimum:
        raise SurfmodError(f"{name}: {purpose} needs at least {minimum}, got {len(items)}")
    return [as_curve(c, f"{name}[{k}]") for k, c in enumerate(items)]
