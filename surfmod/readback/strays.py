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
there: the region it bounds is only known to that distance.  The kernel's side, the
p-curve images and the projections, is :mod:`surfmod.occ.pcurves`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


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
    from ..occ.pcurves import distances_to_curve, edge_images

    out = []
    for e in edge_images(getattr(shape, "wrapped", shape), samples):
        stray = 0.0
        for pts, same in zip(e["images"], e["along"]):
            # at equal parameters (BRepCheck's view): a bound on the true distance that,
            # within the tolerance, already clears the edge; beyond it project each point
            bound = float(np.linalg.norm(pts - same, axis=1).max())
            if bound <= e["tolerance"]:
                stray = max(stray, bound)
                continue
            stray = max(stray, *(min(float(d), bound) for d in distances_to_curve(e["curve"], pts)))
        images = e["images"]
        gap = 0.0
        if len(images) >= 2:
            gap = float(max(np.linalg.norm(a - b, axis=1).max() for a in images for b in images))
        out.append(EdgeStray(e["edge"], tuple(e["faces"]), e["tolerance"], stray, gap, e["length"]))
    return out


def edge_deviations(shape, samples: int = 23) -> np.ndarray:
    """``(E, 2)``: per edge of ``shape`` the largest distance between its 3-D curve and the
    image of its p-curve on each of its faces (``samples`` points, as ``BRepCheck`` does),
    and the edge's length.  A model whose edges are off their faces this far bounds a
    region only up to that distance."""
    from ..occ.pcurves import edge_deviation_samples

    out = [(max([0.0] + [float(np.linalg.norm(ps - p3, axis=1).max()) for ps in images]), length)
           for p3, images, length in edge_deviation_samples(shape, samples)]
    return np.array(out).reshape(-1, 2)
