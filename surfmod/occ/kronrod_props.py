"""A third integrator for mass properties: ``BRepGProp::VolumePropertiesGK`` with its centroid
and inertia flags set, OCCT's adaptive Gauss–Kronrod rule that refines each face until the
volume *and* the first and second moments have converged to ``eps``.

Why beside :mod:`.refined_props`: the split there is exact only where ``ShapeUpgrade``
keeps each face's p-curves.  On files whose p-curves stray it fits them again, the split
solid is another solid, and the refinements do not settle (stepcode_dm1's B-spline
solids, stepcode_TAIL_TURBINE, build123d's screw thread, axom's B-spline sphere).  This
rule integrates the solid as it is and estimates its own error; on those solids it agrees
with surfmod to 1e-12 where plain ``BRepGProp`` (which converges only the volume) is 1e-8
off in inertia (dm1).

Its reference point is its own: the vertex mean, ``BRepGProp``'s rough barycentre, whatever
location the properties object carries, so the same point as surfmod's.  Its time is one
C++ call that no bound estimated beforehand can stop (0.2 s to 60 s on the corpus files at
``eps = 1e-10``), so :func:`kronrod_props_within` runs it in a child process with a
deadline (:mod:`surfmod.child`), the shape passed as OCCT binary BRep bytes.
"""

from __future__ import annotations

import io
import time
from dataclasses import dataclass

import numpy as np
from OCP.BinTools import BinTools
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.TopoDS import TopoDS_Shape

from .. import child
from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .properties import inertia_matrix
from .topo import solids_of


@dataclass(frozen=True)
class KronrodProps:
    """Volume, area, centroid and inertia about the centroid (OCCT's convention, ``Ixy =
    -∫xy``) by the Gauss–Kronrod rule at ``eps``; ``error`` its own estimate of the relative
    error of the whole solid's properties (each quantity relative to its own size)."""

    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray
    eps: float
    error: float
    seconds: float


def kronrod_props(shape, eps: float = 1e-10) -> KronrodProps:
    """Mass properties of the solid ``shape`` by ``BRepGProp.VolumePropertiesGK`` (spans on,
    centroid and inertia converged as well as the volume); the area by
    ``BRepGProp.SurfaceProperties`` at the same ``eps`` (its adaptive rule converges the
    area itself).

    ``error`` is relative to each quantity's own size, a coordinate of the centroid near
    zero included, so it is conservative: a torus centred at the origin reports 8e-9 with
    its volume and inertia exact to 3e-15.

    >>> import build123d as bd, math
    >>> r = kronrod_props(bd.Cylinder(1, 2).wrapped)
    >>> abs(r.volume - 2 * math.pi) < 1e-13, round(float(r.inertia[2, 2] / math.pi), 12), r.error < 1e-12
    (True, 1.0, True)
    """
    if not solids_of(shape):
        raise SurfmodError("shape: has no solid to weigh")
    eps = float(eps)
    if not 1e-15 <= eps < 1:
        raise SurfmodError(f"eps: expected a relative tolerance in [1e-15, 1), got {eps!r}")
    start = time.perf_counter()
    with kernel("BRepGProp.VolumePropertiesGK_s"):
        props = GProp_GProps()
        error = BRepGProp.VolumePropertiesGK_s(shape, props, eps, False, True, True, True)
        area = GProp_GProps()
        BRepGProp.SurfaceProperties_s(shape, area, eps, False)
    if not error >= 0:  # OCCT's sign of a failed integration
        raise SurfmodError("shape: BRepGProp's Gauss-Kronrod rule failed on it")
    return KronrodProps(props.Mass(), area.Mass(), xyz(props.CentreOfMass()), inertia_matrix(props), eps,
                        float(error), time.perf_counter() - start)


def _kronrod_of_bytes(data: bytes, eps: float) -> KronrodProps:
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(data))
    return kronrod_props(shape, eps)


def kronrod_props_within(shape, seconds: float, eps: float = 1e-10) -> KronrodProps:
    """:func:`kronrod_props` in a child process, given ``seconds`` to answer; ``SurfmodError``
    naming ``budget`` when it does not (the child is killed) or dies.

    >>> import build123d as bd
    >>> round(kronrod_props_within(bd.Box(1, 2, 3).wrapped, 60).volume, 12)
    6.0
    """
    if not seconds > 0:
        raise SurfmodError("budget: no time left for the Gauss-Kronrod reference")
    with kernel("BinTools.Write"):
        out = io.BytesIO()
        BinTools.Write_s(shape, out)
    try:
        return child.call(_kronrod_of_bytes, (out.getvalue(), float(eps)), seconds, "the Gauss-Kronrod reference")
    except child.ChildFailure as exc:
        raise SurfmodError(f"budget: {exc}") from None
