"""Moving a NURBS surface (a rational ellipsoid) through geomdl, splipy, rhino3dm (.3dm),
IGES and STEP: degrees, knots and weights come back exactly."""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

e = sm.ellipsoid(50, 30, 20)
(u0, u1), (v0, v1) = e.domain
uu, vv = np.meshgrid(np.linspace(u0, u1, 25), np.linspace(v0, v1, 13))
ref = e.points(uu, vv)


def report(name, back):
    same = (back.degree == e.degree and all(np.array_equal(a, b) for a, b in zip(back.knots, e.knots))
            and np.array_equal(back.weights, e.weights))
    print(f"{name:<8} data identical: {same}, max point difference {np.abs(back.points(uu, vv) - ref).max():.1e}")


report("geomdl", sm.from_geomdl(sm.to_geomdl(e)))
report("splipy", sm.from_splipy(sm.to_splipy(e)))
sm.to_rhino([e], OUT / "nurbs_exchange.3dm")
report(".3dm", sm.from_rhino(OUT / "nurbs_exchange.3dm")[0])
sm.export_iges(e, OUT / "nurbs_exchange.igs")
report("IGES", sm.from_face(sm.import_iges(OUT / "nurbs_exchange.igs").faces()[0]))
sm.export_step(e, OUT / "nurbs_exchange.step")
report("STEP", sm.from_face(sm.import_step(OUT / "nurbs_exchange.step").faces()[0]))
