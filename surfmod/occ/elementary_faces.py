"""The elementary faces of a part (plane, cylinder, cone, sphere, torus) read in one pass:
per face what :func:`surfmod.from_face` would read, for the mass integrals."""

from __future__ import annotations

import numpy as np
import OCP.Geom as G
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_REVERSED

from .guard import kernel


def elementary_faces(faces) -> list:
    """Per ``TopoDS_Face`` of ``faces`` (a part's, for the mass integrals): ``None`` unless
    its surface is a plane, cylinder, cone, sphere or torus (or a
    ``Geom_RectangularTrimmedSurface`` of one), else ``(type name, located surface handle,
    (u0, u1, v0, v1), reversed, frame (4, 3), radii, periodic)`` -- what
    :func:`surfmod.from_face` reads for it (the same OCCT calls and values), without its
    general dispatch, which costs more than the reading on parts of many small faces.
    ``type name`` is the elementary surface's (the basis of a trimmed one), ``periodic``
    whether the face's own surface is periodic in ``u`` and ``v`` (a rectangular trim may
    make it not).

    >>> import build123d as bd
    >>> [(d[0], d[5]) for d in elementary_faces([f.wrapped for f in bd.Cylinder(1, 2).faces()])]
    [('Geom_CylindricalSurface', (1.0,)), ('Geom_Plane', ()), ('Geom_Plane', ())]
    """
    surface_of, uv_bounds = BRep_Tool.Surface_s, BRepTools.UVBounds_s
    reversed_ = TopAbs_REVERSED
    out, frames = [], []
    with kernel("reading elementary faces"):
        for face in faces:
            geom = surface_of(face)  # OCP hands back the derived type already (no DownCast)
            name = geom.DynamicType().Name()
            periodic = _PERIODIC.get(name)
            basis = geom
            if name == "Geom_RectangularTrimmedSurface":
                basis = geom.BasisSurface()
                name = basis.DynamicType().Name()
                periodic = (geom.IsUPeriodic(), geom.IsVPeriodic()) if name in _PERIODIC else None
            if periodic is None:
                out.append(None)
                continue
            if type(basis).__name__ != name:  # an older OCP: the generic handle
                basis = getattr(G, name).DownCast(basis)
            pos = basis.Position()
            frames.append(pos.Location().Coord() + pos.XDirection().Coord() + pos.YDirection().Coord()
                          + pos.Direction().Coord())
            if name == "Geom_Plane":
                radii = ()
            elif name == "Geom_ConicalSurface":
                radii = (basis.RefRadius(), basis.SemiAngle())
            elif name == "Geom_ToroidalSurface":
                radii = (basis.MajorRadius(), basis.MinorRadius())
            else:
                radii = (basis.Radius(),)
            out.append([name, geom, uv_bounds(face), face.Orientation() == reversed_, None, radii, periodic])
    frames = np.array(frames).reshape(-1, 4, 3)  # one array for all frames
    k = 0
    for d in out:
        if d is not None:
            d[4] = frames[k]
            k += 1
    return [None if d is None else tuple(d) for d in out]


# which directions of OCCT's elementary surfaces are periodic (their ``IsUPeriodic``,
# ``IsVPeriodic``; the period is 2π), known without asking
_PERIODIC = {"Geom_Plane": (False, False), "Geom_CylindricalSurface": (True, False),
             "Geom_ConicalSurface": (True, False), "Geom_SphericalSurface": (True, False),
             "Geom_ToroidalSurface": (True, True)}
