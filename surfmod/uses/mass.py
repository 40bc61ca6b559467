"""Mass properties of solids by Gauss quadrature of surface integrals (divergence theorem).

For a solid bounded by faces with outward normal ``n``::

    V        = 1/3 ∮ x·n dA
    ∫ x_i dV = 1/2 ∮ x_i² n_i dA
    ∫ x_i² dV = 1/3 ∮ x_i³ n_i dA,   ∫ x_i x_j dV = 1/2 ∮ x_i² x_j n_i dA  (i ≠ j)

with ``n dA = ± (S_u × S_v) du dv``.  Each face is integrated in its own parameter
domain:

* a face whose boundary is its parameter rectangle (the usual case for surfmod
  surfaces, spheres, tori, cylinders, boxes and most spline faces) by tensor
  Gauss–Legendre on every knot span (quarter turns on periodic directions); the
  result is exact to round-off;
* a trimmed face (holes, faces cut by booleans) by Green's theorem in the parameter
  plane: ``∫∫_D g du dv = ∮ G dv`` with ``G(u, v) = ∫_{u0}^{u} g(s, v) ds``; the outer
  integral runs over Gauss nodes on the exact p-curves of the face's edges (OCCT's
  2-D curves, split at their breaks), the inner one is Gauss in ``u`` on the
  untrimmed surface, split at knots.  No triangulation is involved, so the only error
  is the accuracy of the p-curves themselves (the edge tolerance of the part, about
  1e-7 for boolean results).

Coordinates are shifted to the mean of the solid's vertices (BRepGProp's reference
point) before integrating, which also avoids cancellation.  The inertia tensor is about the centroid, ``I = ρ ∫ (|r|² E − r rᵀ) dV``
(``r`` from the centroid): diagonal ``Ixx = ρ∫(y²+z²)``, off-diagonal ``Ixy = −ρ∫xy``,
the convention of OCCT's ``GProp_GProps.MatrixOfInertia``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import checks
from ..errors import SurfmodError
from .faces import Patch, patches


@dataclass(frozen=True)
class MassProperties:
    """Volume, boundary area, centroid, inertia tensor (about the centroid) and mass.

    ``faces`` counts the faces integrated over their full parameter rectangle
    (``"natural"``) and over a trimmed region by Green's theorem (``"trimmed"``);
    ``evaluators`` says how many faces used the NumPy evaluator vs. OCCT sampling.
    ``error_estimate`` is the relative change of the volume between the requested
    quadrature order and a lower one.

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
    error_estimate: float = 0.0
    method: str = "numpy"

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


def gauss_nodes(breaks: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on every interval between ``breaks``."""
    x, w = np.polynomial.legendre.leggauss(order)
    a, b = breaks[:-1, None], breaks[1:, None]
    nodes = (a + b) / 2 + (b - a) / 2 * x
    weights = (b - a) / 2 * w
    return nodes.ravel(), weights.ravel()


def _moments(ders: np.ndarray, weights: np.ndarray, sign: float, ref: np.ndarray) -> np.ndarray:
    """[area, V, M(3), S(3,3)] contributions from partials at quadrature nodes."""
    # (3, N) rows, contiguous: np.sum then reduces each row pairwise, which keeps the 1e-14
    # of the closed forms (a reduction over axis 0 of (N, 3), or a BLAS dot, does not)
    x = np.ascontiguousarray((ders[:, 0, 0] - ref).T)
    su, sv = ders[:, 1, 0].T, ders[:, 0, 1].T
    n = np.empty_like(x)  # sign * (Su x Sv), written out
    n[0] = su[1] * sv[2] - su[2] * sv[1]
    n[1] = su[2] * sv[0] - su[0] * sv[2]
    n[2] = su[0] * sv[1] - su[1] * sv[0]
    if sign < 0:
        n = -n
    area = float(np.sum(weights * np.sqrt(np.sum(n * n, axis=0))))
    vol = float(np.sum(weights * np.sum(x * n, axis=0))) / 3.0
    a = weights * x**2 * n  # w x_i^2 n_i, (3, N)
    first = np.sum(a, axis=1) / 2.0
    m = np.array([[np.sum(a[i] * x[j]) for j in range(3)] for i in range(3)])  # sum w x_i^2 n_i x_j
    # off the diagonal: symmetric average of the two equivalent divergence forms
    second = (m + m.T) / 4.0
    second[np.diag_indices(3)] = np.sum(weights * x**3 * n, axis=1) / 3.0
    return np.concatenate([[area, vol], first, second.ravel()])


def patch_moments(patch: Patch, ref: np.ndarray, order: int) -> np.ndarray:
    """Moment contributions of one face (see :func:`_moments`)."""
    if patch.natural:
        un, uw = gauss_nodes(patch.breaks_u, order)
        vn, vw = gauss_nodes(patch.breaks_v, order)
        uu, vv = np.meshgrid(un, vn, indexing="ij")
        w = np.outer(uw, vw).ravel()
        return _moments(patch.evaluate(uu.ravel(), vv.ravel(), 1), w, patch.sign, ref)
    return _moments(*green_nodes(patch, order), patch.sign, ref)


def green_nodes(patch: Patch, order: int, base: str = "left"):
    """Partials and weights for ``∫∫_D g du dv = ∮_∂D G dv`` with
    ``G(u, v) = ∫_{u0}^{u} g(s, v) ds``: Gauss on the exact p-curves of the trimming
    boundary, and for each boundary node Gauss in ``u`` from the left edge of the
    face's box to the node (``base="right"``: ``G = -∫_u^{u1} g ds`` from the right
    edge), split at the patch's ``u`` break points.  On a closed boundary both bases give
    the same integral; where the p-curves leave gaps (a model whose edges are off its
    faces) they differ, which is how :func:`mass_properties` measures that ambiguity."""
    from ..occ.uses import face_boundary_nodes

    ub, vb, wb = face_boundary_nodes(patch.face, order, lines_u=patch.breaks_u[1:-1], lines_v=patch.breaks_v[1:-1])
    u0 = patch.bounds[0]
    if np.sum(wb * (ub - u0)) < 0:  # boundary traversed clockwise in (u, v): flip
        wb = -wb
    # nodes on p-curves along v = const carry dv = 0: no inner integral needed there
    moving = wb != 0.0
    ub, vb, wb = ub[moving], vb[moving], wb[moving]
    x, w = np.polynomial.legendre.leggauss(order)
    br = patch.breaks_u
    if base == "left":
        a = np.clip(br[None, :-1], None, ub[:, None])  # (B, S) span starts clipped to node
        b = np.clip(br[None, 1:], None, ub[:, None])
        sign = 1.0
    else:
        a = np.clip(br[None, :-1], ub[:, None], None)
        b = np.clip(br[None, 1:], ub[:, None], None)
        sign = -1.0
    keep = b - a > 0
    bi, si = np.nonzero(keep)
    a, b = a[bi, si], b[bi, si]
    s = ((a + b)[:, None] / 2 + (b - a)[:, None] / 2 * x).ravel()
    ws = sign * ((b - a)[:, None] / 2 * w * wb[bi, None]).ravel()
    vv = np.repeat(vb[bi], order)
    return patch.evaluate(s, vv, 1), ws


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


def mass_properties(obj, density: float = 1.0, *, order: int = 16, method: str = "numpy",
                    eps: float = 1e-9, estimate_error: bool = True) -> MassProperties:
    """Volume, area, centroid and inertia tensor of a solid.

    ``obj`` is a closed surfmod surface (sphere, torus, ...), a list of surfmod
    surfaces/faces that close up (they are sewn), a build123d ``Solid``/``Compound``,
    an OCP shape or a STEP file path.  ``method="numpy"`` (default) integrates with
    Gauss quadrature on the NumPy evaluator (see the module notes); ``method="occt"``
    returns OCCT's ``BRepGProp`` at relative tolerance ``eps`` instead (the
    cross-check).  ``estimate_error=False`` skips the second, lower-order quadrature behind
    ``error_estimate`` (then NaN), about 40 % of the time.  Open shells are sewn at the
    model's tolerance; those that stay open raise ``SurfmodError``.

    >>> import surfmod as sm, build123d as bd
    >>> r = sm.mass_properties(bd.Box(2, 3, 4))
    >>> round(r.volume, 12), round(r.area, 12)
    (24.0, 52.0)
    >>> [round(float(x), 12) for x in r.inertia.diagonal()]
    [50.0, 40.0, 26.0]
    """
    from ..occ import uses as occ
    from .inputs import to_shape

    density = checks.positive(density, "density")
    order = checks.count(order, "order", minimum=2)
    if method not in ("numpy", "occt"):
        raise SurfmodError(f"method: expected 'numpy' or 'occt', got {method!r}")
    solid = to_shape(obj, "obj", solid=True)
    if method == "occt":
        g = occ.gprops(solid, eps)
        return MassProperties(g["volume"], g["area"], g["centroid"], density * g["inertia"], density,
                              method=f"occt BRepGProp eps={eps:g}", error_estimate=float(g["volume_error"]))
    # the reference point of the surface integrals: the mean of the vertices, as BRepGProp
    # takes it.  On a boundary that closes exactly any point gives the same result; on a
    # real file whose faces leave gaps (edges off their faces) the integrals depend on it
    # by (shift . closure defect) / 3, so the same point makes the two comparable.
    ref = occ.vertex_mean(solid)
    from ..surface import Surface

    if isinstance(obj, Surface):
        # one closed surface (sphere, torus, ...): integrate its own NumPy evaluator over
        # its domain; the orientation is fixed by the sign of the enclosed volume
        from .faces import surface_patch

        pats = [surface_patch(obj)]
        probe = patch_moments(pats[0], ref, order)
        if probe[1] < 0:
            from dataclasses import replace

            pats = [replace(pats[0], sign=-1.0)]
    else:
        pats = patches(solid)
    total = np.zeros(14)
    low = np.zeros(14)
    low_order = max(2, order - 4)
    for p in pats:
        total += patch_moments(p, ref, order)
        if estimate_error:
            low += patch_moments(p, ref, low_order)
    vol, area, centroid, inertia = _finish(total, ref, density)
    nat = sum(p.natural for p in pats)
    est = abs(total[1] - low[1]) / vol if estimate_error else float("nan")
    return MassProperties(
        vol, area, centroid, inertia, density,
        faces={"natural": nat, "trimmed": len(pats) - nat},
        evaluators={"numpy": sum(p.evaluator == "numpy" for p in pats), "occt": sum(p.evaluator == "occt" for p in pats)},
        error_estimate=float(est),
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
    from .inputs import to_shape

    solid = to_shape(obj, "obj", solid=True)
    box = occ.bounding_box(solid)
    r = float(np.linalg.norm(box[1] - box[0])) / 2
    volume = occ.gprops(solid, 1e-6)["volume"]
    dev = occ.edge_deviations(solid)
    return float(np.sum(dev[:, 0] * dev[:, 1]) * r / 3 / volume) if len(dev) else 0.0
