"""Mass properties of solids: :func:`mass_properties` reads its input (a surfmod surface,
faces, a build123d shape, a STEP path) and hands the faces read back to the quadrature
pipeline of :mod:`surfmod.mass`; ``method="occt"`` returns OCCT's ``BRepGProp`` instead (the
cross-check).  The same concept as :mod:`surfmod.cli.mass` (the ``surfmod mass`` command over
this).  See :doc:`/guide/uses` (section "How a face is integrated").
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import checks
from ..errors import InsideOutWarning, SurfmodError
from ..inputs import to_shape
from ..mass.totals import MassProperties, integrate
from ..readback import from_faces
from ..readback.strays import edge_deviations
from ..surface import Surface


def mass_properties(obj, density: float = 1.0, *, order: int = 12, method: str = "numpy",
                    eps: float = 1e-9, estimate_error: bool = True) -> MassProperties:
    """Volume, area, centroid and inertia tensor of a solid.

    ``obj`` is a closed surfmod surface (sphere, torus, ...), a list of surfmod
    surfaces/faces that close up (they are sewn), a build123d ``Solid``/``Compound``,
    an OCP shape or a STEP file path.  ``method="numpy"`` (default) integrates with
    Gauss quadrature on the NumPy evaluator (see the module notes); ``method="occt"``
    returns OCCT's ``BRepGProp`` at relative tolerance ``eps`` instead (the
    cross-check).  ``order`` is the Gauss order per piece where the integrand is not a
    polynomial of known degree (angles, rational splines, curved p-curves); polynomial
    directions get the order that is exact for them.  ``estimate_error=False`` drops the
    second, lower-order quadrature behind ``error_estimate`` (then NaN); otherwise it runs
    when ``error_estimate`` is first read.  Open shells are sewn at the model's
    tolerance; those that stay open raise ``SurfmodError``.

    >>> import surfmod as sm, build123d as bd
    >>> r = sm.mass_properties(bd.Box(2, 3, 4))
    >>> round(r.volume, 12), round(r.area, 12)
    (24.0, 52.0)
    >>> [round(float(x), 12) for x in r.inertia.diagonal()]
    [50.0, 40.0, 26.0]
    """
    from ..occ.properties import gprops, vertex_mean
    from ..occ.topo import faces_of, solids_of

    density = checks.positive(density, "density")
    order = checks.count(order, "order", minimum=2)
    if method not in ("numpy", "occt"):
        raise SurfmodError(f"method: expected 'numpy' or 'occt', got {method!r}")
    # each solid is turned outward by the sign of the volume measured below, not by a
    # BRepGProp pass of its own first (that pass was a third of the time on small parts)
    solid = to_shape(obj, "obj", solid=True, outward=False)
    inside_out: list = []
    if method == "occt":
        g = gprops(solid, eps, inside_out)
        r = MassProperties(g["volume"], g["area"], g["centroid"], density * g["inertia"], density,
                           method=f"occt BRepGProp eps={eps:g}", _error=float(g["volume_error"]))
    else:
        # the reference point of the surface integrals: the mean of the vertices, as
        # BRepGProp takes it.  On a boundary that closes exactly any point gives the same
        # result; on a real file whose faces leave gaps (edges off their faces) the integrals
        # depend on it by (shift . closure defect) / 3, so the same point makes the two comparable.
        ref = vertex_mean(solid)
        if isinstance(obj, Surface):
            return integrate(obj, ref, density, order, estimate_error)
        faces, numbers = [], []
        for k, part in enumerate(solids_of(solid) or [solid]):  # sewn faces: one solid
            mine = faces_of(part)
            faces += mine
            numbers += [k] * len(mine)
        r = integrate(from_faces(faces), ref, density, order, estimate_error, solids=numbers, inside_out=inside_out)
    for number, volume in inside_out:  # as closed_solid says it of the solids it turns itself
        warnings.warn(f"solid {number} is inside out (enclosed volume {volume:.6g}): turned outward",
                      InsideOutWarning, stacklevel=2)
    return r


def boundary_ambiguity(obj) -> float:
    """How far a solid's own data leaves its volume open, relative to the volume.

    Each edge's 3-D curve and the images of its p-curves on its faces should coincide;
    real files carry them apart by up to the edge tolerance (and beyond).  Moving a
    boundary curve of length ``L`` by ``d`` across a face changes the enclosed volume by at
    most ``d L r / 3`` (``r`` the half diagonal of the bounding box), so the bound is
    ``Σ d_e L_e r / (3 V)``.  Two correct integrators may differ by up to this much.

    >>> import surfmod as sm, build123d as bd
    >>> sm.boundary_ambiguity(bd.Box(1, 2, 3)) < 1e-12
    True
    """
    from ..occ.properties import bounding_box, gprops

    solid = to_shape(obj, "obj", solid=True, outward=False)  # the bound's size, not its sign
    box = bounding_box(solid)
    r = float(np.linalg.norm(box[1] - box[0])) / 2
    volume = abs(gprops(solid, 1e-6)["volume"])
    dev = edge_deviations(solid)
    return float(np.sum(dev[:, 0] * dev[:, 1]) * r / 3 / volume) if len(dev) else 0.0
