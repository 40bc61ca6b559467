"""Interference between mating parts: overlap volume, minimum distance, contact (OCCT's
Boolean and distance: :mod:`surfmod.occ.booleans`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..inputs import to_shape


@dataclass(frozen=True)
class Interference:
    """Report of :func:`interference`.

    ``overlap_volume`` is the volume of the boolean common of the parts
    (``BRepAlgoAPI_Common``); ``distance`` the minimum distance between them
    (``BRepExtrema_DistShapeShape``, 0 when they touch or overlap) with the closest
    points ``point_a``/``point_b``; ``contact`` is True when the parts touch
    (distance ≤ ``tolerance``) without overlapping volume; ``interferes`` when the
    overlap volume exceeds ``tolerance`` times the smaller part's volume.

    >>> import surfmod as sm, build123d as bd
    >>> r = sm.interference(bd.Box(2, 2, 2), bd.Pos(1.5, 0, 0) * bd.Box(2, 2, 2))
    >>> round(r.overlap_volume, 9), r.interferes
    (2.0, True)
    """

    overlap_volume: float
    distance: float
    point_a: np.ndarray
    point_b: np.ndarray
    contact: bool
    interferes: bool
    volume_a: float
    volume_b: float
    tolerance: float

    @property
    def status(self) -> str:
        if self.interferes:
            return "interference"
        return "contact" if self.contact else "clearance"

    def __str__(self) -> str:
        a, b = self.point_a, self.point_b
        pct = 100.0 * self.overlap_volume / min(self.volume_a, self.volume_b)
        return (
            f"interference report: {self.status.upper()}\n"
            f"  overlap volume   {self.overlap_volume:.9g} ({pct:.3g} % of the smaller part)\n"
            f"  minimum distance {self.distance:.9g}\n"
            f"  closest points   a ({a[0]:.6g}, {a[1]:.6g}, {a[2]:.6g})  b ({b[0]:.6g}, {b[1]:.6g}, {b[2]:.6g})\n"
            f"  volumes          a {self.volume_a:.9g}  b {self.volume_b:.9g}\n"
            f"  contact          {'yes' if self.contact else 'no'} (tolerance {self.tolerance:g})"
        )


def interference(a, b, tolerance: float = 1e-6) -> Interference:
    """Overlap volume, minimum distance and contact between two solids.

    ``a`` and ``b`` are anything :func:`surfmod.mass_properties` accepts (build123d
    solids, closed lists of surfmod surfaces, STEP paths).

    >>> import surfmod as sm, build123d as bd
    >>> r = sm.interference(bd.Box(2, 2, 2), bd.Box(2, 2, 2).translate((1.5, 0, 0)))
    >>> round(r.overlap_volume, 9), r.status
    (2.0, 'interference')
    >>> r = sm.interference(bd.Box(2, 2, 2), bd.Sphere(1).translate((3, 0, 0)))
    >>> round(r.distance, 9), r.status
    (1.0, 'clearance')
    """
    from ..occ.booleans import common_volume, min_distance
    from ..occ.properties import bounding_box, gprops

    tolerance = checks.positive(tolerance, "tolerance")
    sa = to_shape(a, "a", solid=True)
    sb = to_shape(b, "b", solid=True)
    box = np.concatenate([bounding_box(sa, optimal=False), bounding_box(sb, optimal=False)])
    # a contact distance below round-off of the pair's size is no request (the volume
    # share uses the same number: at most 1, since the overlap is at most the smaller part)
    checks.tolerance(tolerance, "tolerance", float(np.linalg.norm(np.ptp(box, axis=0))))
    va = gprops(sa)["volume"]
    vb = gprops(sb)["volume"]
    overlap = common_volume(sa, sb)
    dist, pa, pb, _inner = min_distance(sa, sb)
    interferes = overlap > tolerance * min(va, vb)
    if interferes:
        dist = 0.0
    else:
        overlap = max(overlap, 0.0)
    contact = (not interferes) and dist <= tolerance
    return Interference(float(overlap), float(dist), pa, pb, bool(contact), bool(interferes),
                        float(va), float(vb), tolerance)
