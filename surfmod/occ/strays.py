"""How far each edge's p-curves stray from its 3-D curve and from each other, measured
without BRepCheck, beside the tolerance the edge declares.

``BRepCheck`` compares the 3-D curve and a p-curve's image at equal parameters and calls a
solid valid when they agree within the edge's tolerance; real files carry p-curves that
stray far beyond it (a sphere-cylinder circle whose 2-D trim lies 0.9 mm off the 3-D
circle at tolerance 5e-6) while BRepCheck is content.  Here every p-curve image point is
projected onto the 3-D curve (``GeomAPI_ProjectPointOnCurve``: the true distance, whatever
the parametrizations; the distance at equal parameters, BRepCheck's, bounds it and is
taken where it is already within the tolerance), and the images on the edge's two faces are compared with each
other at equal parameters (they bound the two faces: where they part, the faces do not
share a boundary).  An edge whose stray exceeds its tolerance leaves the model ambiguous
there: the region it bounds is only known to that distance.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepGProp import BRepGProp
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp

from .arrays import pnt, xyz, xyz_many
from .guard import kernel
from .topo import geometric_edges, pcurve_points
from .bindings import TopTools_IndexedMapOfShape


class EdgeStray(NamedTuple):
    """One edge: its index (``TopExp`` edge map order, from 0), the indices of its faces
    (``TopExp`` face map order, from 0), its declared ``tolerance``, the largest distance of
    a p-curve image from the 3-D curve (``stray``; where within the tolerance, the bound at
    equal parameters), the largest distance between the images
    on its faces at equal parameters (``gap``, 0 for an edge of one face) and its length."""

    edge: int
    faces: tuple
    tolerance: float
    stray: float
    gap: float
    length: float

    @property
    def ambiguous(self) -> bool:
        """The p-curves stray beyond what the edge declares."""
        return max(self.stray, self.gap) > self.tolerance


def edge_strays(shape, samples: int = 17) -> list[EdgeStray]:
    """:class:`EdgeStray` for every geometric, non-degenerate edge of ``shape`` (``samples``
    points per p-curve; about ``2 E samples`` point projections in all).

    >>> import build123d as bd
    >>> [e.ambiguous for e in edge_strays(bd.Box(1, 2, 3).wrapped)][:3]
    [False, False, False]
    """
    shape = getattr(shape, "wrapped", shape)
    out = []
    with kernel("edge strays (GeomAPI_ProjectPointOnCurve)"):
        fmap = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(shape, TopAbs_FACE, fmap)
        for edge_index, edge, edge_faces in geometric_edges(shape):
            range_ = BRepAdaptor_Curve(edge)
            first, last = range_.FirstParameter(), range_.LastParameter()
            curve = BRep_Tool.Curve_s(edge, first, last)  # a located copy of the 3-D curve
            if curve is None:
                continue
            project = GeomAPI_ProjectPointOnCurve()
            project.Init(curve, first, last)
            images, faces, stray = [], [], 0.0
            for face in edge_faces:
                if face.IsNull():
                    continue
                index = fmap.FindIndex(face) - 1
                if index in faces:  # a seam edge: the same face twice (two p-curves)
                    continue
                faces.append(index)
                t, pts = pcurve_points(edge, face, samples)
                images.append(pts)
                tolerance = BRep_Tool.Tolerance_s(edge)
                # at equal parameters (BRepCheck's view): a bound on the true distance that,
                # within the tolerance, already clears the edge; beyond it project each point
                same = xyz_many((curve.Value(x) for x in t.tolist()), len(t))
                bound = float(np.linalg.norm(pts - same, axis=1).max())
                if bound <= tolerance:
                    stray = max(stray, bound)
                    continue
                for p in pts:
                    project.Perform(pnt(p))
                    # no orthogonal foot (beyond the curve's ends): the nearer end is the distance
                    d = project.LowerDistance() if project.NbPoints() > 0 else min(
                        np.linalg.norm(p - xyz(curve.Value(first))), np.linalg.norm(p - xyz(curve.Value(last))))
                    stray = max(stray, min(float(d), bound))
            gap = 0.0
            if len(images) >= 2:
                gap = float(max(np.linalg.norm(a - b, axis=1).max() for a in images for b in images))
            props = GProp_GProps()
            BRepGProp.LinearProperties_s(edge, props)
            out.append(EdgeStray(edge_index, tuple(faces), float(BRep_Tool.Tolerance_s(edge)), stray, gap, props.Mass()))
    return out


def edge_deviations(shape, samples: int = 23) -> np.ndarray:
    """``(E, 2)``: per edge of ``shape`` the largest distance between its 3-D curve and the
    image of its p-curve on each of its faces (``samples`` points, as ``BRepCheck`` does),
    and the edge's length.  A model whose edges are off their faces this far bounds a
    region only up to that distance."""
    out = []
    with kernel("edge deviations"):
        for _, edge, edge_faces in geometric_edges(shape):
            c3 = BRepAdaptor_Curve(edge)
            t = np.linspace(c3.FirstParameter(), c3.LastParameter(), samples)
            p3 = xyz_many((c3.Value(x) for x in t.tolist()), samples)
            dev = 0.0
            for face in edge_faces:
                _, ps = pcurve_points(edge, face, samples)
                dev = max(dev, float(np.linalg.norm(ps - p3, axis=1).max()))
            props = GProp_GProps()
            BRepGProp.LinearProperties_s(edge, props)
            out.append((dev, props.Mass()))
    return np.array(out).reshape(-1, 2)
