"""OCCT twins only the tests and benchmarks use: independent references written against
OCP directly (mass by plane cuts, hidden lines, GeomAPI intersection and projection, gp
transforms).  They live beside the tests, not in the package: no surfmod code calls them."""
