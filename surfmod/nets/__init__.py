"""Control-net surfaces and curves: Bézier, B-spline/NURBS, Hermite (frozen values)."""
