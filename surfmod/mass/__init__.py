"""Mass properties of solids by Gauss quadrature of surface integrals (the divergence theorem), to round-off.

One pipeline whose stages are modules, each calling only the ones before it:
:mod:`~surfmod.mass.rules`, :mod:`~surfmod.mass.breaks`, :mod:`~surfmod.mass.boundary`,
:mod:`~surfmod.mass.nodes`, :mod:`~surfmod.mass.planes`, :mod:`~surfmod.mass.moments`,
:mod:`~surfmod.mass.totals`.  :func:`surfmod.mass_properties` (:mod:`surfmod.uses.mass`) calls
:func:`~surfmod.mass.totals.integrate`; ``TrimmedFace.area()`` calls
:func:`~surfmod.mass.moments.face_moments`.  The fields and the reference point are
BRepGProp's, so that where a file's boundary does not close both compute the same quantity;
keep them so.  See :doc:`/design_layers` (section "Mass properties: one pipeline") and
:doc:`/guide/uses` (section "How a face is integrated").
"""
