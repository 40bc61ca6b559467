"""Mass properties of solids by Gauss quadrature of surface integrals (divergence theorem).

For a solid bounded by faces with outward normal ``n``::

    V        = 1/3 ∮ x·n dA
    ∫ x_i dV = 1/2 ∮ x_i² n_i dA
    ∫ x_i² dV = 1/3 ∮ x_i³ n_i dA,   ∫ x_i x_j dV = 1/2 ∮ x_i² x_j n_i dA  (i ≠ j)

with ``n dA = ± (S_u × S_v) du dv``.  Each face is integrated in its own parameter
domain:

* a face whose boundary is its parameter rectangle (the usual case for surfmod
  surfaces, spheres, tori, cylinders, boxes and most spline faces) by tensor
  Gauss–Legendre on every knot span (eighth turns on angular directions); the
  result is exact to round-off;
* a trimmed face (holes, faces cut by booleans) by Green's theorem in the parameter
  plane: ``∫∫_D g du dv = ∮ G dv`` with ``G(u, v) = ∫_{u0}^{u} g(s, v) ds`` (or the same
  along ``v``); the outer integral runs over Gauss nodes on the exact p-curves of the
  face's edges (OCCT's 2-D curves, split at their breaks), the inner one runs on the
  untrimmed surface, split at knots (Gauss per boundary node, or one interpolation grid
  per knot cell shared by all boundary nodes: see :mod:`surfmod.uses.mass_green`).  No triangulation is involved, so the only
  error is the accuracy of the p-curves themselves (the edge tolerance of the part,
  about 1e-7 for boolean results).

The node count is what costs, so :mod:`surfmod.uses.mass_green` gives every direction
and piece the fewest nodes that keep the result at round-off: Gauss orders from the
surface's polynomial degree (planes and the axes of cylinders and cones are integrated
exactly with 3 nodes), Green's inner integral along the cheaper direction (the axis of a
cylinder, not its angle) where the p-curves join up, p-curves evaluated from their data
for all nodes at once, and the moment sums of many faces in one pass.  Where a face's
p-curves leave gaps the result depends on the direction, and the one BRepGProp takes
(``u``) is kept.

Coordinates are shifted to the mean of the solid's vertices (BRepGProp's reference
point) before integrating, which also avoids cancellation.  The inertia tensor is about the centroid, ``I = ρ ∫ (|r|² E − r rᵀ) dV``
(``r`` from the centroid): diagonal ``Ixx = ρ∫(y²+z²)``, off-diagonal ``Ixy = −ρ∫xy``,
the convention of OCCT's ``GProp_GProps.MatrixOfInertia``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import checks
from ..construct.elementary import ConicalSurface, CylindricalSurface, PlaneSurface, SphericalSurface, ToroidalSurface
from ..errors import SurfmodError
from ..readback import from_face
from ..readback.trimmed import TrimmedFace
from ..surface import Surface
from .inputs import to_shape
from .mass_green import (
    face_nodes,
    faces_nodes,
    mass_face,
    mass_faces,
    plane_nodes,
    prepare_boundaries,
    surface_mass_face,
    taylor_pieces,
)
from .mass_plane import plane_moments


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


def _moments(ders: np.ndarray, weights: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """[area, V, M(3), S(3,3)] contributions from partials at quadrature nodes (``Su``
    already signed so that ``Su × Sv`` is the outward ``n dA``)."""
    return _moments_of_groups(ders, weights, ref, [0, len(weights)])[0]


def _moments_of_groups(ders: np.ndarray, weights: np.ndarray, ref: np.ndarray, bounds) -> np.ndarray:
    """``(G, 14)``: :func:`_moments` of the node groups ``[bounds[g], bounds[g + 1])``,
    the integrands computed once for all of them and summed group by group (each sum the
    one the group's own call makes, bit for bit: contiguous rows, pairwise)."""
    # (3, N) rows, contiguous: np.sum then reduces each row pairwise, which keeps the 1e-14
    # of the closed forms (a reduction over axis 0 of (N, 3), or a BLAS dot, does not)
    x = np.ascontiguousarray((ders[:, 0, 0] - ref).T)
    su, sv = ders[:, 1, 0].T, ders[:, 0, 1].T
    n = np.empty_like(x)  # Su x Sv, written out
    n[0] = su[1] * sv[2] - su[2] * sv[1]
    n[1] = su[2] * sv[0] - su[0] * sv[2]
    n[2] = su[0] * sv[1] - su[1] * sv[0]
    area = weights * np.sqrt(np.sum(n * n, axis=0))
    vol = weights * np.sum(x * n, axis=0)
    a = weights * x**2 * n  # w x_i^2 n_i, (3, N)
    ax = a * x
    cross = a[:, None, :] * x[None, :, :]  # w x_i^2 n_i x_j, (3, 3, N)
    out = np.empty((len(bounds) - 1, 14))
    for g, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:])):
        m = np.sum(cross[:, :, lo:hi], axis=2)  # sum w x_i^2 n_i x_j
        # off the diagonal: symmetric average of the two equivalent divergence forms
        second = (m + m.T) / 4.0
        second[np.diag_indices(3)] = np.sum(ax[:, lo:hi], axis=1) / 3.0
        out[g, 0] = float(np.sum(area[lo:hi]))
        out[g, 1] = float(np.sum(vol[lo:hi])) / 3.0
        out[g, 2:5] = np.sum(a[:, lo:hi], axis=1) / 2.0
        out[g, 5:] = second.ravel()
    return out


class _Accumulator:
    """Sums :func:`_moments` over many faces in ``groups`` separate totals (e.g. rules
    exact by degree and the others), evaluating them in batches of about ``BATCH`` nodes
    (one NumPy pass for many small faces and both groups, bounded memory for big ones)."""

    BATCH = 200_000

    def __init__(self, ref: np.ndarray, groups: int = 1):
        self.ref, self.totals, self.size = ref, np.zeros((groups, 14)), 0
        self.parts = [[] for _ in range(groups)]

    def add(self, ders: np.ndarray, weights: np.ndarray, group: int = 0) -> None:
        self.parts[group].append((ders, weights))
        self.size += len(weights)
        if self.size >= self.BATCH:
            self.flush()

    def flush(self) -> np.ndarray:
        """The totals, ``(groups, 14)`` (one group: its row)."""
        pieces = [piece for parts in self.parts for piece in parts]
        if pieces:
            counts = [sum(len(w) for _, w in parts) for parts in self.parts]
            ders = np.concatenate([d for d, _ in pieces]) if len(pieces) > 1 else pieces[0][0]
            weights = np.concatenate([w for _, w in pieces]) if len(pieces) > 1 else pieces[0][1]
            bounds = np.concatenate([[0], np.cumsum(counts)])
            live = [g for g, c in enumerate(counts) if c]  # an empty group adds nothing
            sums = _moments_of_groups(ders, weights, self.ref, bounds)
            self.totals[live] += sums[live]
            self.parts, self.size = [[] for _ in self.parts], 0
        return self.totals[0] if len(self.totals) == 1 else self.totals


def face_moments(face, ref=(0.0, 0.0, 0.0), order: int = 12) -> np.ndarray:
    """``[area, V, M(3), S(3, 3)]`` of one face read back with :func:`surfmod.from_face`
    (its trimmed region; ``V`` etc. are the face's share of the divergence-theorem
    integrals about ``ref``).

    >>> import surfmod as sm, build123d as bd
    >>> round(float(face_moments(sm.from_face(bd.Box(2, 3, 4).faces()[0]))[0]), 12)
    12.0
    """
    ders, w, _ = face_nodes(mass_face(face), order)
    return _moments(ders, w, np.asarray(ref, dtype=float))


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


_ELEMENTARY = {
    "Geom_Plane": PlaneSurface, "Geom_CylindricalSurface": CylindricalSurface, "Geom_ConicalSurface": ConicalSurface,
    "Geom_SphericalSurface": SphericalSurface, "Geom_ToroidalSurface": ToroidalSurface,
}


def _read_faces(shapes: list) -> list:
    """:func:`surfmod.from_face` of every face of a part: the same ``TrimmedFace``, the
    elementary ones (planes, cylinders, cones, spheres, tori: most faces of real parts)
    built from one pass over their OCCT data (:func:`surfmod.occ.uses.elementary_faces`)."""
    from ..occ import uses as occ

    out = []
    for shape, data in zip(shapes, occ.elementary_faces(shapes)):
        if data is None:
            out.append(from_face(shape))
            continue
        name, geom, bounds, reversed_, frame, radii, periodic = data
        u0, u1, v0, v1 = bounds
        surface = _ELEMENTARY[name]._trusted(frame, radii, (u0, u1), (v0, v1))
        out.append(TrimmedFace(surface, shape, geom, bounds, _elementary_periods(periodic, bounds), reversed_))
    return out


def _elementary_periods(periodic, bounds) -> tuple:
    """readback's ``_periods`` of an elementary surface over ``bounds`` (``periodic``: per
    direction whether OCCT's surface is periodic; the period is then 2π): 2π where the
    direction is periodic and the face spans one whole period, else None."""
    period = 2 * np.pi
    spans = (bounds[1] - bounds[0], bounds[3] - bounds[2])
    return tuple(period if periodic and abs(span - period) <= 1e-9 * period else None
                 for periodic, span in zip(periodic, spans))


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
    from ..occ import uses as occ

    density = checks.positive(density, "density")
    order = checks.count(order, "order", minimum=2)
    if method not in ("numpy", "occt"):
        raise SurfmodError(f"method: expected 'numpy' or 'occt', got {method!r}")
    solid = to_shape(obj, "obj", solid=True)
    if method == "occt":
        g = occ.gprops(solid, eps)
        return MassProperties(g["volume"], g["area"], g["centroid"], density * g["inertia"], density,
                              method=f"occt BRepGProp eps={eps:g}", _error=float(g["volume_error"]))
    # the reference point of the surface integrals: the mean of the vertices, as BRepGProp
    # takes it.  On a boundary that closes exactly any point gives the same result; on a
    # real file whose faces leave gaps (edges off their faces) the integrals depend on it
    # by (shift . closure defect) / 3, so the same point makes the two comparable.
    ref = occ.vertex_mean(solid)

    if isinstance(obj, Surface):
        # one closed surface (sphere, torus, ...): integrate its own NumPy evaluator over
        # its domain; the orientation is fixed by the sign of the enclosed volume
        faces = [surface_mass_face(obj)]
        if _moments(*face_nodes(faces[0], order)[:2], ref)[1] < 0:
            faces[0].sign = -1.0
    else:
        from ..occ.pcurves import faces_pcurves
        from ..occ.topo import faces_of

        read = _read_faces(faces_of(solid))
        pcurves = faces_pcurves([f.face_shape for f in read])  # B-splines in one table
        taylor_pieces([rec for pcs in pcurves for rec in pcs])  # all B-spline p-curves at once
        faces = mass_faces(read, pcurves)
        prepare_boundaries(faces, order)  # the p-curves of all trimmed faces in one pass
    # faces whose every rule is exact by degree give the same sums at any order: the
    # lower-order pass behind the error estimate only re-integrates the others
    # two totals: faces whose every rule is exact by degree (0) and the others (1)
    sums = _Accumulator(ref, groups=2)
    inexact = []
    planes = [f for f in faces if f.plane and f.natural and f.frame is not None]
    if planes:  # whole planar rectangles (most faces of prismatic parts): all at once
        sums.add(*plane_nodes(planes))
    # trimmed planar faces: closed form from their boundary moments, all at once
    trimmed_planes = [f for f in faces if f.plane and not f.natural and f.frame is not None]
    inexact_planes = []
    if trimmed_planes:
        closed, is_exact = plane_moments(trimmed_planes, order, ref)
        sums.totals[0] += closed[is_exact].sum(axis=0)
        sums.totals[1] += closed[~is_exact].sum(axis=0)
        inexact_planes = [f for f, e in zip(trimmed_planes, is_exact) if not e]
    curved = [f for f in faces if not (f.plane and f.frame is not None)]
    for f, (ders, w, is_exact) in zip(curved, faces_nodes(curved, order)):  # small Green grids shared
        sums.add(ders, w, 0 if is_exact else 1)
        if not is_exact:
            inexact.append(f)
    exact_total, high_total = sums.flush()
    total = exact_total + high_total
    vol, area, centroid, inertia = _finish(total, ref, density)
    nat = sum(f.natural for f in faces)

    def estimate() -> float:
        low = _Accumulator(ref)
        for f in inexact:
            low.add(*face_nodes(f, max(2, order - 4))[:2])
        if inexact_planes:
            low.totals[0] += plane_moments(inexact_planes, max(2, order - 4), ref)[0].sum(axis=0)
        return abs(high_total[1] - low.flush()[1]) / vol

    return MassProperties(
        vol, area, centroid, inertia, density,
        faces={"natural": nat, "trimmed": len(faces) - nat},
        evaluators={"numpy": len(faces), "occt": 0},
        _error=estimate if estimate_error else float("nan"),
    )


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
    from ..occ import uses as occ

    solid = to_shape(obj, "obj", solid=True)
    box = occ.bounding_box(solid)
    r = float(np.linalg.norm(box[1] - box[0])) / 2
    volume = occ.gprops(solid, 1e-6)["volume"]
    dev = occ.edge_deviations(solid)
    return float(np.sum(dev[:, 0] * dev[:, 1]) * r / 3 / volume) if len(dev) else 0.0
