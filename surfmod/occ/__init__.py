"""The one door to OpenCASCADE: the only package in surfmod that imports OCP.

Modules here convert NumPy arrays to OCCT containers and back, build ``Geom_*`` objects,
sample OCCT for cross-checks, make faces/edges/shapes and read/write exchange files.
Every call that can throw runs inside :func:`surfmod.occ.guard.kernel`.  Algorithms over
what these calls return belong above the door, with the concept they serve; the OCCT twins
only tests use live in ``tests/twins``.
"""
