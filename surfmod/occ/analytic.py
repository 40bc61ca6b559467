"""OCCT analytic curves and surfaces (conics, elementary surfaces, swept analytic
surfaces, offset and trimmed surfaces, GeomFill ruled surfaces): builders from surfmod
data and readers back to plain NumPy data.

Frames are passed as ``(origin, x_dir, y_dir, z_dir)`` NumPy arrays; an indirect frame
(``x ^ y = -z``, e.g. after a mirror) becomes an indirect ``gp_Ax3``.
"""

from __future__ import annotations

import numpy as np
from OCP.gp import gp_Ax1, gp_Ax2, gp_Ax3, gp_Dir, gp_Trsf

from ..errors import SurfmodError
from .arrays import pnt, xyz
from .guard import kernel
from OCP.Geom import (Geom_Circle, Geom_ConicalSurface, Geom_CylindricalSurface, Geom_Ellipse, Geom_Hyperbola,
    Geom_Line, Geom_OffsetSurface, Geom_Parabola, Geom_Plane, Geom_SphericalSurface,
    Geom_SurfaceOfLinearExtrusion, Geom_SurfaceOfRevolution, Geom_ToroidalSurface, Geom_TrimmedCurve)
from OCP.GeomFill import GeomFill
from OCP.gp import gp_Circ, gp_Elips, gp_Hypr, gp_Lin, gp_Parab
from .geom import read_bspline_curve


def _dir(v) -> gp_Dir:
    return gp_Dir(float(v[0]), float(v[1]), float(v[2]))


def ax3(frame) -> gp_Ax3:
    """``gp_Ax3`` from ``(origin, x, y, z)``; indirect when ``x ^ y`` opposes ``z``."""
    o, x, y, z = frame
    with kernel("gp_Ax3"):
        a = gp_Ax3(pnt(o), _dir(z), _dir(x))
        if float(np.dot(np.cross(z, x), y)) < 0.0:
            a.YReverse()
        return a


def ax2(origin, normal, x_dir) -> gp_Ax2:
    with kernel("gp_Ax2"):
        return gp_Ax2(pnt(origin), _dir(normal), _dir(x_dir))


def read_ax3(pos) -> tuple:
    """``(origin, x, y, z)`` of a ``gp_Ax3`` / ``gp_Ax2``."""
    return xyz(pos.Location()), xyz(pos.XDirection()), xyz(pos.YDirection()), xyz(pos.Direction())


# -- curves ---------------------------------------------------------------------------------
#: conic -> (Geom class, gp class, the numbers after its frame: read-back key -> getter)
_CONICS = {
    "circle": (Geom_Circle, gp_Circ, {"radius": "Radius"}),
    "ellipse": (Geom_Ellipse, gp_Elips, {"major": "MajorRadius", "minor": "MinorRadius"}),
    "parabola": (Geom_Parabola, gp_Parab, {"focal": "Focal"}),
    "hyperbola": (Geom_Hyperbola, gp_Hypr, {"major": "MajorRadius", "minor": "MinorRadius"}),
}


def conic(kind: str, origin, normal, x_dir, *numbers):
    """The ``Geom_*`` conic ``kind`` (a key of ``_CONICS``) in the frame
    ``gp_Ax2(origin, normal, x_dir)`` with its numbers in the table's order."""
    geom, gp, _ = _CONICS[kind]
    with kernel(geom.__name__):
        return geom(gp(ax2(origin, normal, x_dir), *map(float, numbers)))


def infinite_line(origin, direction):
    with kernel("Geom_Line"):
        return Geom_Line(gp_Lin(pnt(origin), _dir(direction)))


def trimmed(curve, t0, t1):
    with kernel("Geom_TrimmedCurve"):
        return Geom_TrimmedCurve(curve, float(t0), float(t1))


_CONIC_NAMES = {geom.__name__: (kind, fields) for kind, (geom, _, fields) in _CONICS.items()}


def _numbers(geom, fields: dict) -> dict:
    return {key: getattr(geom, getter)() for key, getter in fields.items()}


def read_curve(curve) -> dict:
    """Plain data of an OCCT curve in its own parametrization.

    ``kind`` is one of ``line``, ``circle``, ``ellipse``, ``parabola``, ``hyperbola``,
    ``bspline``, ``bezier``;
    trimmed curves are unwrapped (the caller keeps the parameter range).
    """
    name = curve.DynamicType().Name()
    with kernel(f"reading {name}"):
        if name == "Geom_TrimmedCurve":
            return read_curve(curve.BasisCurve())
        if name == "Geom_Line":
            lin = curve.Lin()
            return {"kind": "line", "origin": xyz(lin.Location()), "direction": xyz(lin.Direction())}
        if (found := _CONIC_NAMES.get(name)) is not None:
            kind, fields = found
            return {"kind": kind, "frame": read_ax3(curve.Position()), **_numbers(curve, fields)}
        if name == "Geom_BSplineCurve":
            return {"kind": "bspline", **read_bspline_curve(curve)}
        if name == "Geom_BezierCurve":
            poles = range(1, curve.NbPoles() + 1)
            w = np.array([curve.Weight(i) for i in poles]) if curve.IsRational() else None
            return {"kind": "bezier", "points": np.array([xyz(curve.Pole(i)) for i in poles]), "weights": w}
    raise SurfmodError(f"curve: unsupported OCCT curve type {name}")


# -- elementary surfaces ----------------------------------------------------------------------
#: surface -> (Geom class, the numbers after its frame in the constructor's order: read-back key -> getter)
_ELEMENTARY = {
    "plane": (Geom_Plane, {}),
    "cylinder": (Geom_CylindricalSurface, {"radius": "Radius"}),
    "cone": (Geom_ConicalSurface, {"semi_angle": "SemiAngle", "radius": "RefRadius"}),
    "sphere": (Geom_SphericalSurface, {"radius": "Radius"}),
    "torus": (Geom_ToroidalSurface, {"major": "MajorRadius", "minor": "MinorRadius"}),
}
_ELEMENTARY_FIELDS = {geom.__name__: fields for geom, fields in _ELEMENTARY.values()}


def elementary(kind: str, frame, *numbers):
    """The ``Geom_*`` elementary surface ``kind`` (a key of ``_ELEMENTARY``) on
    ``ax3(frame)`` with its numbers in the table's order."""
    geom, _ = _ELEMENTARY[kind]
    with kernel(geom.__name__):
        return geom(ax3(frame), *map(float, numbers))


def read_elementary(surf) -> dict:
    """Frame and radii of a downcast Geom_Plane / Cylindrical / Conical / Spherical / Toroidal surface."""
    name = surf.DynamicType().Name()
    with kernel(f"reading {name}"):
        return {"kind": name, "frame": read_ax3(surf.Position()), **_numbers(surf, _ELEMENTARY_FIELDS.get(name, {}))}


# -- swept analytic surfaces --------------------------------------------------------------------
def revolution(basis_curve, origin, direction):
    with kernel("Geom_SurfaceOfRevolution"):
        return Geom_SurfaceOfRevolution(basis_curve, gp_Ax1(pnt(origin), _dir(direction)))


def extrusion(basis_curve, direction):
    with kernel("Geom_SurfaceOfLinearExtrusion"):
        return Geom_SurfaceOfLinearExtrusion(basis_curve, _dir(direction))


def read_revolution(surf) -> dict:
    with kernel("reading Geom_SurfaceOfRevolution"):
        axis = surf.Axis()
        return {"basis": surf.BasisCurve(), "origin": xyz(axis.Location()), "direction": xyz(axis.Direction())}


def read_extrusion(surf) -> dict:
    with kernel("reading Geom_SurfaceOfLinearExtrusion"):
        return {"basis": surf.BasisCurve(), "direction": xyz(surf.Direction())}


def offset_surface(basis, distance):
    with kernel("Geom_OffsetSurface"):
        return Geom_OffsetSurface(basis, float(distance))


def read_offset(surf) -> dict:
    with kernel("reading Geom_OffsetSurface"):
        return {"basis": surf.BasisSurface(), "distance": surf.Offset()}


def read_trimmed_surface(surf) -> dict:
    with kernel("reading Geom_RectangularTrimmedSurface"):
        return {"basis": surf.BasisSurface(), "bounds": tuple(surf.Bounds())}


def ruled(curve1, curve2):
    """OCCT's ruled surface between two curves (``GeomFill::Surface``)."""
    with kernel("GeomFill::Surface"):
        return GeomFill.Surface_s(curve1, curve2)


def trsf(matrix) -> gp_Trsf:
    """``gp_Trsf`` of a 4x4 similarity matrix (rotation/mirror times uniform scale)."""
    m = np.asarray(matrix, dtype=float)
    t = gp_Trsf()
    with kernel("gp_Trsf.SetValues"):
        t.SetValues(*(float(x) for x in m[:3, :4].ravel()))
    return t
