"""Stage seven of the mass pipeline (:mod:`surfmod.mass`): every face of a part to its
volume, area, centroid and inertia tensor (:class:`MassProperties`), with the error
estimate of a lower-order pass.

>>> import surfmod as sm
>>> r = integrate(sm.sphere(2.0), np.zeros(3))
>>> round(r.volume / (32 / 3 * np.pi), 12)
1.0
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import SurfmodError
from ..surface import Surface
from .moments import MomentAccumulator, node_moments
from .nodes import face_nodes, faces_nodes, mass_faces, plane_nodes, prepare_boundaries, surface_mass_face, taylor_pieces
from .planes import plane_moments


@dataclass(frozen=True)
class MassProperties:
    """Volume, boundary area, centroid, inertia tensor (about the centroid) and mass.

    ``faces`` counts the faces integrated over their full parameter rectangle
    (``"natural"``) and over a trimmed region by Green's theorem (``"trimmed"``);
    ``evaluators`` says how many faces used the NumPy evaluator vs. OCCT sampling.
    ``error_estimate`` is the relative change of the volume between the requested
    quadrature order and a lower one; the lower-order pass behind it runs the first time
    it is read (most callers never do), and faces integrated exactly by degree are not
    re-integrated (their change is zero).

    >>> import surfmod as sm, build123d as bd
    >>> m = sm.mass_properties(bd.Box(1, 2, 3))
    >>> round(m.volume, 12), round(m.area, 12)
    (6.0, 22.0)
    """

    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray
    density: float = 1.0
    faces: dict = field(default_factory=dict)
    evaluators: dict = field(default_factory=dict)
    method: str = "numpy"
    # a float, or a function computing it on first use (see ``error_estimate``)
    _error: object = field(default=0.0, repr=False, compare=False)

    @property
    def error_estimate(self) -> float:
        """Relative change of the volume between the requested Gauss order and one four
        lower (NaN when not requested; BRepGProp's own estimate for ``method="occt"``)."""
        if callable(self._error):
            object.__setattr__(self, "_error", float(self._error()))
        return self._error

    @property
    def mass(self) -> float:
        return self.density * self.volume

    @property
    def principal_moments(self) -> np.ndarray:
        """Eigenvalues of the inertia tensor, ascending."""
        return np.linalg.eigvalsh(self.inertia)

    def __str__(self) -> str:
        c = self.centroid
        rows = "\n".join("    [" + "  ".join(f"{x: .9g}" for x in r) + "]" for r in self.inertia)
        return (
            f"mass properties ({self.method}, density {self.density:g})\n"
            f"  volume   {self.volume:.12g}\n  mass     {self.mass:.12g}\n  area     {self.area:.12g}\n"
            f"  centroid ({c[0]:.10g}, {c[1]:.10g}, {c[2]:.10g})\n"
            f"  inertia about the centroid (Ixy = -∫xy dm):\n{rows}\n"
            + (f"  faces    {self.faces}\n" if self.faces else "")
        )


def _finish(total: np.ndarray, ref: np.ndarray, density: float):
    area, vol = total[0], total[1]
    if not vol > 0:
        raise SurfmodError(f"obj: the boundary encloses no positive volume (got {vol:.3g}); is it a closed, outward-oriented solid?")
    c = total[2:5] / vol
    second = total[5:].reshape(3, 3)
    second = (second + second.T) / 2
    central = second - vol * np.outer(c, c)
    inertia = density * (np.trace(central) * np.eye(3) - central)
    return float(vol), float(area), ref + c, inertia


def integrate(obj, ref: np.ndarray, density: float = 1.0, order: int = 12, estimate_error: bool = True, *,
              solids=None, inside_out: list | None = None) -> MassProperties:
    """:class:`MassProperties` of one closed surfmod surface ``obj`` (its NumPy evaluator
    over its domain), or of the faces of a closed solid read back (a list of
    ``TrimmedFace``, :func:`surfmod.readback.from_faces`), integrated about the point
    ``ref`` (see :func:`surfmod.mass_properties` for ``order`` and ``estimate_error``).

    ``solids`` gives the solid (numbered from 0) of each face read back: each solid's
    moments are summed apart, and a solid whose enclosed volume comes out negative (its
    faces point into its material) counts turned outward as a whole, its ``(number from
    1, volume)`` appended to ``inside_out`` (a list).  So the volume that orients a solid
    is the one measured, computed once.  Without ``solids`` the faces are one solid."""
    # the p-curves' reader is in the kernel door, loaded on the first call that needs OCP
    from ..occ.pcurves import faces_pcurves

    if isinstance(obj, Surface):
        # one closed surface (sphere, torus, ...): integrate its own NumPy evaluator over
        # its domain; the orientation is fixed by the sign of the enclosed volume
        faces = [surface_mass_face(obj)]
        if node_moments(*face_nodes(faces[0], order)[:2], ref)[1] < 0:
            faces[0].sign = -1.0
    else:
        read = obj
        pcurves = faces_pcurves([f.face_shape for f in read])  # B-splines in one table
        taylor_pieces([rec for pcs in pcurves for rec in pcs])  # all B-spline p-curves at once
        faces = mass_faces(read, pcurves)
        prepare_boundaries(faces, order)  # the p-curves of all trimmed faces in one pass
    number = np.zeros(len(faces), dtype=int) if solids is None or isinstance(obj, Surface) else np.asarray(solids)
    if len(number) != len(faces):
        raise SurfmodError(f"solids: {len(number)} solid numbers for {len(faces)} faces")
    count = int(number.max(initial=0)) + 1
    solid_of = {id(f): int(n) for f, n in zip(faces, number)}
    # faces whose every rule is exact by degree give the same sums at any order: the
    # lower-order pass behind the error estimate only re-integrates the others.  Two
    # totals per solid: faces whose every rule is exact by degree (2 s) and the others (2 s + 1)
    sums = MomentAccumulator(ref, groups=2 * count)
    inexact = []
    planes = [f for f in faces if f.plane and f.natural and f.frame is not None]
    for s in range(count):  # whole planar rectangles (most faces of prismatic parts): all at once
        mine = [f for f in planes if solid_of[id(f)] == s]
        if mine:
            sums.add(*plane_nodes(mine), 2 * s)
    # trimmed planar faces: closed form from their boundary moments, all at once
    trimmed_planes = [f for f in faces if f.plane and not f.natural and f.frame is not None]
    inexact_planes = []
    if trimmed_planes:
        closed, is_exact = plane_moments(trimmed_planes, order, ref)
        owner = np.array([solid_of[id(f)] for f in trimmed_planes])
        for s in np.unique(owner):
            sums.totals[2 * s] += closed[is_exact & (owner == s)].sum(axis=0)
            sums.totals[2 * s + 1] += closed[~is_exact & (owner == s)].sum(axis=0)
        inexact_planes = [f for f, e in zip(trimmed_planes, is_exact) if not e]
    curved = [f for f in faces if not (f.plane and f.frame is not None)]
    for f, (ders, w, is_exact) in zip(curved, faces_nodes(curved, order)):  # small Green grids shared
        sums.add(ders, w, 2 * solid_of[id(f)] + (0 if is_exact else 1))
        if not is_exact:
            inexact.append(f)
    totals = np.atleast_2d(sums.flush()).reshape(count, 2, 14)
    turned = totals[:, :, 1].sum(axis=1) < 0  # per solid: its faces point inwards
    for s in np.flatnonzero(turned):
        if inside_out is not None:
            inside_out.append((int(s) + 1, float(totals[s, :, 1].sum())))
        totals[s, :, 1:] *= -1.0  # volume and moments change sign with the faces; the area does not
    exact_total, high_total = totals[:, 0].sum(axis=0), totals[:, 1].sum(axis=0)
    total = exact_total + high_total
    vol, area, centroid, inertia = _finish(total, ref, density)
    nat = sum(f.natural for f in faces)

    def estimate() -> float:
        low = MomentAccumulator(ref, groups=count)
        for f in inexact:
            low.add(*face_nodes(f, max(2, order - 4))[:2], solid_of[id(f)])
        if inexact_planes:
            rows = plane_moments(inexact_planes, max(2, order - 4), ref)[0]
            owner = np.array([solid_of[id(f)] for f in inexact_planes])
            for s in np.unique(owner):
                low.totals[s] += rows[owner == s].sum(axis=0)
        low_total = np.atleast_2d(low.flush()).copy()
        low_total[turned, 1:] *= -1.0
        return abs(high_total[1] - low_total.sum(axis=0)[1]) / vol

    return MassProperties(
        vol, area, centroid, inertia, density,
        faces={"natural": nat, "trimmed": len(faces) - nat},
        evaluators={"numpy": len(faces), "occt": 0},
        _error=estimate if estimate_error else float("nan"),
    )
