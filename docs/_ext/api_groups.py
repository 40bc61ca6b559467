"""The sections of the API reference: title, one sentence, the public names in it.

Names that ``surfmod.__all__`` no longer has are skipped; names it has that no group
lists are documented under "Other public names", so the page never falls behind.
"""

GROUPS = [
    ("Surfaces and curves", "The protocol every surface and curve follows, and the control-net entities.",
     ["Surface", "Curve", "Curvatures", "BSplineSurface", "BezierSurface", "HermiteBicubic",
      "BSplineCurve", "BezierCurve"]),
    ("Curves", "Lines and conics; any build123d edge is read with ``from_edge``.",
     ["Line", "Circle", "Arc", "Ellipse", "Parabola", "Hyperbola", "from_edge"]),
    ("Synthetic and analytic surfaces", "The lecture's constructors, each with its OCCT twin.",
     ["plane", "ThreePointPlane", "PlaneSurface", "CylindricalSurface", "ConicalSurface",
      "SphericalSurface", "ToroidalSurface", "ruled", "RuledSurface", "tabulated_cylinder",
      "TabulatedCylinder", "revolution", "RevolutionSurface", "sweep", "SweptSurface", "loft",
      "LoftSurface", "sphere", "torus", "ellipsoid", "Ellipsoid", "superellipsoid", "Superellipsoid",
      "explicit", "ExplicitSurface", "implicit", "ImplicitSurface", "to_implicit"]),
    ("Fitting, networks, blends, fills, offsets", "Surfaces made from data or from other surfaces.",
     ["interpolate", "approximate", "FittedSurface", "fit", "Fit", "coons", "CoonsSurface",
      "gordon", "GordonSurface", "blend", "BlendSurface", "fill", "Fill", "offset", "thicken",
      "OffsetApproximation", "OffsetSurface"]),
    ("Real parts and checking", "Faces of STEP files read back into NumPy, the cross-check against OCCT, and "
     "any evaluator held against OCCT and a 40-digit reference.",
     ["import_step", "from_face", "TrimmedFace", "crosscheck", "CrossCheck", "conformance", "Conformance"]),
    ("Meshing and display", "Grid meshes, verified tessellation, iso-curves, shaded pictures.",
     ["Mesh", "mesh", "tessellate", "isocurves", "IsoCurves", "IsoCurve", "render", "export_stl"]),
    ("Subdivision", "Catmull–Clark and Loop subdivision, limit points, limit surfaces as CAD patches.",
     ["catmull_clark", "loop_subdivide", "catmull_clark_limit", "loop_limit", "LimitPoints",
      "limit_surface", "LimitSurface"]),
    ("Trimming, intersection, projection", "Operations on surfaces and faces.",
     ["trim", "trimmed_area", "intersect", "intersect_line", "IntersectionCurve", "project",
      "Projection", "shadow", "Shadow"]),
    ("Analysis", "Continuity across boundaries, curvature pictures and fairness.",
     ["continuity", "Continuity", "analyze", "Analysis"]),
    ("Uses of surface models", "Solids, mass properties, interference, sections, finite element meshes.",
     ["make_solid", "mass_properties", "boundary_ambiguity", "MassProperties", "interference",
      "Interference", "section", "Section", "export_dxf", "export_svg", "fe_mesh", "FEMesh",
      "export_fe_mesh"]),
    ("CAM", "Tools, tool paths and G-code.",
     ["Tool", "toolpath", "Toolpath", "export_gcode"]),
    ("Exchange", "STEP, IGES, the NURBS libraries geomdl, splipy and rhino3dm, and build123d's viewer.",
     ["export_step", "export_iges", "import_iges", "to_geomdl", "from_geomdl", "to_splipy",
      "from_splipy", "to_rhino", "from_rhino", "to_build123d"]),
    ("Errors and settings", "The exceptions of the error contract, and the thread cap of the kernels.",
     ["SurfmodError", "KernelError", "DamagedFileError", "MissingExtraError", "RoundTripWarning", "InsideOutWarning",
      "set_threads"]),
]
