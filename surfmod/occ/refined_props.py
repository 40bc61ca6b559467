"""A second, independent reference for mass properties: ``BRepGProp`` on the same solid with
every face split into ``k × k`` iso-parametric pieces, ``k = 1, 2, 4, 8``, until two
refinements agree.

Why it is needed: ``BRepGProp``'s adaptive rule stops when the *volume* of each face has
converged to its ``eps``; the first and second moments are summed on the same nodes and
converge more slowly, so on a torus of nist_ftc_11 its inertia stays 5e-7 off the closed
form (mpmath, from the profile) at ``eps = 1e-13``, where surfmod's is within 3e-16.  Its
moments do converge when the faces are smaller: split ``2 × 2`` the same solid gives the
closed form to 2e-14.

Why the split changes nothing but the quadrature: the pieces are cut along iso-parametric
lines of each face's own surface (``ShapeUpgrade_ShapeDivideArea`` by numbers), so every
piece keeps the face's surface and the pieces of its p-curves, and the new edges between
two pieces carry the same p-curve on both sides with opposite orientations: their
contributions cancel, and the sum over the pieces is the face's integral exactly.  All
faces are integrated about one point, the *original* solid's vertex mean (BRepGProp's own
reference point, which surfmod takes too), not the split solid's: on a real file whose
edges leave gaps the integrals depend on that point, and with the same point and the same
(radial) fields surfmod and this reference compute one and the same quantity.

The estimate of its error is the change of the last refinement (Gauss rules converge
geometrically in the piece size, so the finer result is better than that); the run stops
when the change is below :data:`CONVERGED` or at ``k = 8``, and refuses up front when the
next refinement would take longer than ``budget`` (four times the pieces of the last one).
Where edges stray off their faces the split is not exact (``ShapeUpgrade`` fits their
p-curves again) and the refinements do not settle: their changes, the estimate, stay
large (1e-9 to 1e-2 on the corpus files whose p-curves stray, on build123d's screw thread
and on axom's B-spline sphere; below 1e-10 on the others), and the reference cannot
judge there.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from OCP.BRepGProp import BRepGProp, BRepGProp_Domain, BRepGProp_Face, BRepGProp_Vinert
from OCP.GProp import GProp_GProps
from OCP.ShapeUpgrade import ShapeUpgrade_ShapeDivideArea
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_REVERSED
from OCP.gp import gp_Pnt

from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .properties import inertia_matrix, relative_differences, vertex_mean
from .topo import faces_of, solids_of

#: the pieces per face direction, coarsest first
SPLITS = (1, 2, 4, 8)


@dataclass(frozen=True)
class RefinedProps:
    """Volume, area, centroid and inertia about the centroid (OCCT's convention, ``Ixy =
    -∫xy``) at the finest refinement ``splits`` run, integrated about ``location``;
    ``changes`` the last refinement's change of the volume and area (relative), the
    centroid (relative to the volume's cube root) and the inertia (relative to its largest
    entry): the error estimate."""

    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray
    location: np.ndarray
    splits: int
    faces: int
    changes: dict
    seconds: float

    @property
    def converged(self) -> bool:
        return max(self.changes.values()) <= CONVERGED


#: the change of one refinement below which the reference is taken as settled
CONVERGED = 1e-11


def split_faces(shape, k: int):
    """``shape`` with every face split into about ``k × k`` pieces along iso-parametric lines
    of its surface (the same surfaces and p-curve pieces; ``k = 1``: the shape itself)."""
    if k == 1:
        return shape
    with kernel("ShapeUpgrade_ShapeDivideArea"):
        divide = ShapeUpgrade_ShapeDivideArea(shape)
        divide.SetSplittingByNumber(True)
        divide.SetNumbersUVSplits(k, k)
        if not divide.Perform():
            return shape  # nothing to split (one planar face, say): the shape as it is
        return divide.Result()


def gprops_about(shape, location, eps: float = 1e-13) -> GProp_GProps:
    """``BRepGProp``'s volume integrals of ``shape`` about the point ``location``, face by face
    as ``BRepGProp::VolumeProperties`` takes them (forward and reversed faces, the domain of
    a trimmed face, the adaptive rule at ``eps``), but about a point the caller chooses."""
    p = gp_Pnt(*map(float, location))
    total = GProp_GProps(gp_Pnt(0, 0, 0))
    with kernel("BRepGProp_Vinert"):
        vinert = BRepGProp_Vinert()
        vinert.SetLocation(p)
        for face in faces_of(shape):
            if face.Orientation() not in (TopAbs_FORWARD, TopAbs_REVERSED):
                continue  # internal and external faces bound no volume
            bf = BRepGProp_Face()
            bf.Load(face)
            domain = BRepGProp_Domain()
            if face.NbChildren() != 0:
                domain.Init(face)
            vinert.Perform(bf, domain, float(eps))
            total.Add(vinert, 1.0)
    return total


class _Props(NamedTuple):
    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray


def _props(shape, location, eps) -> _Props:
    """BRepGProp's volume, area, centroid and inertia of ``shape``, the volume integrals
    about ``location`` (the area is the same about any point)."""
    g = gprops_about(shape, location, eps)
    area = GProp_GProps()
    with kernel("BRepGProp.SurfaceProperties_s"):
        BRepGProp.SurfaceProperties_s(shape, area, float(eps), False)
    return _Props(g.Mass(), area.Mass(), xyz(g.CentreOfMass()), inertia_matrix(g))


def refined_props(shape, *, location=None, eps: float = 1e-13, budget: float = 60.0) -> RefinedProps:
    """Volume, area, centroid and inertia of the solid ``shape`` by ``BRepGProp`` on its faces
    split ``k × k`` (``k`` in :data:`SPLITS`, until a refinement changes every quantity by
    less than :data:`CONVERGED`), all about ``location`` (default: the vertex mean of the
    shape, BRepGProp's and surfmod's reference point).  ``SurfmodError`` naming ``budget``
    when the next refinement would take longer than the seconds left (estimated as four
    times the last one, before it starts).

    >>> import build123d as bd
    >>> r = refined_props(bd.Torus(10, 2).wrapped)
    >>> round(r.volume, 9), bool(r.converged), r.splits
    (789.568352087, True, 2)
    """
    if not solids_of(shape):
        raise SurfmodError("shape: has no solid to weigh")
    location = vertex_mean(shape) if location is None else np.asarray(location, dtype=float)
    start = time.perf_counter()
    previous, changes, last = None, {}, 0.0
    for k in SPLITS:
        now = time.perf_counter()
        if previous is not None and now + 4 * last > start + budget:
            raise SurfmodError(f"budget: refining the faces {k} x {k} would take about {4 * last:.0f} s, more than the "
                               f"{start + budget - now:.0f} s left of {budget:g} s")
        split = split_faces(shape, k)
        current = _props(split, location, eps)
        last = time.perf_counter() - now
        if previous is not None:
            changes = relative_differences(previous, current)
            if max(changes.values()) <= CONVERGED:
                break
        previous = current
    return RefinedProps(*current, location, k, len(faces_of(split)), changes, time.perf_counter() - start)
