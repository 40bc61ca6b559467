"""Mass properties of solids by Gauss quadrature of surface integrals (divergence theorem),
as one pipeline whose stages are modules, each calling only the ones before it:

1. :mod:`~surfmod.mass.rules`: Gauss–Legendre and Chebyshev rules, Green's theorem grids;
2. :mod:`~surfmod.mass.breaks`: where a face's parametrization breaks into pieces;
3. :mod:`~surfmod.mass.boundary`: the boundary pieces (p-curves cut at the breaks) and
   their Gauss nodes;
4. :mod:`~surfmod.mass.nodes`: faces prepared for quadrature (``MassFace``) and their
   nodes and weights (tensor rules or Green's theorem);
5. :mod:`~surfmod.mass.planes`: trimmed planar faces in closed form;
6. :mod:`~surfmod.mass.moments`: the moment integrands summed over the nodes;
7. :mod:`~surfmod.mass.totals`: all faces of a part to volume, centroid and inertia.

The data goes one way: faces read back (:func:`surfmod.from_face`, one package up) →
boundary pieces → nodes and rules → moments → totals.  :func:`surfmod.mass_properties`
(:mod:`surfmod.uses.mass`) reads its input and calls :func:`~surfmod.mass.totals.integrate`;
``TrimmedFace.area()`` calls :func:`~surfmod.mass.moments.face_moments`.  The one
independent reference (BRepGProp on split faces, its Gauss–Kronrod rule) and the verdict
of ``surfmod mass`` are :mod:`surfmod.uses.mass_reference`, one level up.

For a solid bounded by faces with outward normal ``n`` (``x`` from the reference point)::

    V            = 1/3 ∮ (x·n) dA
    ∫ x_i dV     = 1/4 ∮ x_i (x·n) dA
    ∫ x_i x_j dV = 1/5 ∮ x_i x_j (x·n) dA

with ``n dA = ± (S_u × S_v) du dv``: the radial fields ``x^k x / (3 + k)``, whose
divergence is the monomial ``x^k``.  They are BRepGProp's, and they turn with the part:
on a boundary that closes every divergence-free field adds nothing, but on a real file
whose edges leave gaps the result depends on the fields, and per-axis ones
(``x_i² n_i / 2``) make it depend on the orientation of the coordinate frame (on
axom_boxed_sphere.step a rotation moved their inertia by 3e-3, where the radial fields
give the same tensor turned, to round-off).  Each face is integrated in its own parameter
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
  per knot cell shared by all boundary nodes: see :mod:`surfmod.mass.nodes`).  No triangulation is involved, so the only
  error is the accuracy of the p-curves themselves (the edge tolerance of the part,
  about 1e-7 for boolean results).

The node count is what costs, so :mod:`surfmod.mass.nodes` gives every direction
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
