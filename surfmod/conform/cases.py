"""The cases an evaluator is held against (``"stress"``, ``"lecture"``, ``"corpus"`` or a STEP
path): control-net surfaces and curves, each with the parameters it is sampled at.

Samples sit beside interior knots, not on them (where a partial the surface lacks jumps
and either side's value is right), at the domain ends and in the shortest spans.
See :doc:`/guide/real_parts` (section "Holding your own evaluator against OCCT").
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..errors import SurfmodError
from ..gallery import entries
from ..interop.common import nurbs_of
from ..io.step_iges import import_step
from ..nets.bezier import BezierCurve, BezierSurface
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..readback import from_faces

#: the real-parts corpus of the repository
CORPUS = Path(__file__).resolve().parents[2] / "tests" / "data" / "step"
#: parameter values per direction of a stress or lecture case (a surface case is their grid)
SAMPLES = 6
#: per direction for a face of a STEP file (the reference is computed, not cached, there)
FILE_SAMPLES = 3


class Case(NamedTuple):
    """One case: ``name``; ``obj`` a ``BSplineSurface``/``BezierSurface`` or
    ``BSplineCurve``/``BezierCurve``; ``u`` and ``v`` the sample parameters (flat arrays of
    equal length; ``v`` is None for a curve)."""

    name: str
    obj: object
    u: np.ndarray
    v: np.ndarray | None

    @property
    def is_curve(self) -> bool:
        return self.v is None

    def fingerprint(self) -> str:
        """A digest of the definition and the samples: a cached reference is the case's
        only while the digest matches."""
        o = self.obj
        knots = o.knots if self.is_curve else np.concatenate(o.knots)
        parts = [o.control_points, np.atleast_1d(o.degree).astype(float), knots,
                 np.zeros(0) if o.weights is None else o.weights, self.u, np.zeros(0) if self.v is None else self.v]
        h = hashlib.sha256()
        for a in parts:
            h.update(np.ascontiguousarray(a, dtype=float).tobytes())
            h.update(b"|")
        return h.hexdigest()[:16]


def stress_parameters(knots, degree: int, n_ctrl: int, count: int, bounds=None) -> np.ndarray:
    """``count`` sample values of one direction (see the module notes): the domain ends
    (or ``bounds``), beside the interior knots nearest the shortest spans, the middle of
    the shortest spans, then evenly between.

    >>> t = stress_parameters(np.array([0, 0, 0, 1e-4, 1, 1, 1.0]), 2, 4, 5)   # the short span first
    >>> print(np.array2string(t, precision=6))
    [0.00e+00 5.00e-05 7.50e-05 9.99e-05 1.00e+00]
    """
    k = np.asarray(knots, dtype=float)
    lo, hi = (float(k[degree]), float(k[n_ctrl])) if bounds is None else (float(bounds[0]), float(bounds[1]))
    lo, hi = max(lo, float(k[degree])), min(hi, float(k[n_ctrl]))
    inner = np.unique(k[(k > lo) & (k < hi)])
    breaks = np.concatenate([[lo], inner, [hi]])
    spans = np.diff(breaks)
    picks = [lo, hi]
    for s in np.argsort(spans, kind="stable"):
        a, b = breaks[s], breaks[s + 1]
        picks += [0.5 * (a + b), a + 1e-3 * (b - a) if a > lo else 0.25 * (a + 3 * b), b - 1e-3 * (b - a)]
    picks += list(np.linspace(lo, hi, count + 2)[1:-1])
    out: list[float] = []
    for t in picks:  # first come, first kept: the ends, then the shortest spans' points
        if len(out) < count and t not in out:
            out.append(float(t))
    return np.sort(np.array(out))


def _surface_case(name: str, s, count: int = SAMPLES, bounds=None) -> Case:
    (p, q), (ku, kv) = s.degree, s.knots
    n, m = s.control_points.shape[:2]
    (bu, bv) = bounds if bounds is not None else (None, None)
    uu, vv = np.meshgrid(stress_parameters(ku, p, n, count, bu), stress_parameters(kv, q, m, count, bv),
                         indexing="ij")
    return Case(name, s, uu.ravel(), vv.ravel())


def _curve_case(name: str, c, count: int = 3 * SAMPLES) -> Case:
    return Case(name, c, stress_parameters(c.knots, c.degree, len(c.control_points), count), None)


def _net(rng, n: int, m: int, size=(10.0, 8.0), bump: float = 1.0) -> np.ndarray:
    """A seeded, wavy ``(n, m, 3)`` net over ``[0, size[0]] x [0, size[1]]``."""
    x, y = np.meshgrid(np.linspace(0, size[0], n), np.linspace(0, size[1], m), indexing="ij")
    z = bump * (np.sin(0.9 * x) * np.cos(0.7 * y) + rng.uniform(-0.3, 0.3, (n, m)))
    return np.stack([x + rng.uniform(-0.1, 0.1, (n, m)), y + rng.uniform(-0.1, 0.1, (n, m)), z], axis=-1)


def _clamped(p: int, inner, lo: float = 0.0, hi: float = 1.0) -> np.ndarray:
    return np.concatenate([[lo] * (p + 1), np.asarray(inner, dtype=float), [hi] * (p + 1)])


def _crowded(p: int, gaps, lo: float, hi: float) -> np.ndarray:
    """Clamped knots on ``[lo, hi]`` whose interior knots cluster: after the knot at 0.4 of
    the domain come knots ``gaps`` (fractions of the domain) apart, then long spans."""
    w = hi - lo
    inner = [0.4]
    for g in gaps:
        inner.append(inner[-1] + g)
    inner += [0.7, 0.85]
    return _clamped(p, lo + w * np.array(inner), lo, hi)


def stress_cases() -> list[Case]:
    """The stress family (see the module notes), built from seeded random nets.

    >>> cases = stress_cases()
    >>> len(cases) > 20, sum(c.is_curve for c in cases) >= 4
    (True, True)
    """
    rng = np.random.default_rng(35)
    out = []

    def bs(name, net, deg, knots, weights=None):
        out.append(_surface_case(name, BSplineSurface(net, deg, knots, weights)))

    # crowded knots: the three shapes the issue found on real parts, then 1e-6 .. 1e-3
    lo, w = -0.25, 1.0
    inner = np.sort(np.concatenate([lo + w * np.linspace(0, 1, 16)[1:-1], lo + w * (0.41 + 1e-5 * np.arange(1, 4))]))
    ku = _clamped(3, inner, lo, lo + w)
    bs("21 x 4 bicubic, crowded u, domain below 0", _net(rng, len(ku) - 4, 4), (3, 3), (ku, _clamped(3, [])))
    k5 = _clamped(5, np.repeat(np.linspace(0, 189, 7)[1:-1], 3), 0.0, 189.0)
    bs("21 x 6 quintic, 0..189, triple knots", _net(rng, len(k5) - 6, 6, (189.0, 50.0)), (5, 5),
       (k5, _clamped(5, [])))
    kv = _clamped(3, np.repeat(np.linspace(0, 1, 23)[1:-1], 2))
    bs("4 x 48 bicubic, double v-knots", _net(rng, 4, len(kv) - 4), (3, 3), (_clamped(3, []), kv))
    for gap in (1e-6, 1e-5, 1e-4, 1e-3):
        k = _crowded(3, [gap, gap], 0.0, 1.0)
        bs(f"crowded {gap:.0e} bicubic", _net(rng, len(k) - 4, len(k) - 4), (3, 3), (k, k))
    # parameter ranges 1e-3 .. 1e4 wide, offset from zero
    for lo, width in ((5.0, 1e-3), (-3e3, 1e4), (1e3, 2.5), (-7.0, 0.1)):
        k = _clamped(3, lo + width * np.array([0.2, 0.45, 0.5, 0.8]), lo, lo + width)
        bs(f"range {width:g} from {lo:g}", _net(rng, 8, 8), (3, 3), (k, k))
    # degrees 1 .. 9 with interior knots of multiplicity 1 .. p; Bézier up to 25
    for p in range(1, 10):
        k = _clamped(p, np.concatenate([[0.3], [0.6] * p]))
        bs(f"degree {p}, a knot of multiplicity {p}", _net(rng, len(k) - p - 1, len(k) - p - 1), (p, p), (k, k))
    for p in (12, 25):
        out.append(_surface_case(f"Bezier degree {p} x 3", BezierSurface(_net(rng, p + 1, 4, bump=0.3))))
    # weights up to 1e4 apart, with crowded knots
    k = _crowded(3, [1e-4, 1e-4], 0.0, 2.0)
    w = 10.0 ** rng.uniform(0, 4, (len(k) - 4, len(k) - 4))
    bs("NURBS, weights 1..1e4, crowded", _net(rng, len(k) - 4, len(k) - 4), (3, 3), (k, k), w)
    out.append(_surface_case("rational Bezier, weights 1..1e4",
                             BezierSurface(_net(rng, 6, 5), 10.0 ** rng.uniform(0, 4, (6, 5)))))
    # coordinates 1e6 from the origin
    k = _crowded(3, [1e-5, 1e-5], 0.0, 1.0)
    bs("1e6 from the origin, crowded", _net(rng, len(k) - 4, 7) + [1e6, -1e6, 1e6], (3, 3), (k, _clamped(3, [0.5] * 3)))
    # periodic: a closed net on uniform unclamped knots (OCCT's periodic form, unwrapped)
    ring = _net(rng, 9, 6)
    t = np.linspace(0, 2 * np.pi, 9, endpoint=False)
    ring[..., 0], ring[..., 1] = (5 + ring[..., 2]) * np.cos(t)[:, None], (5 + ring[..., 2]) * np.sin(t)[:, None]
    ring[..., 2] = np.linspace(0, 8, 6)[None, :]
    net = np.concatenate([ring, ring[:3]])
    bs("periodic bicubic, closed in u", net, (3, 3), (np.arange(-3.0, len(net) + 1.0), _clamped(3, [0.5, 0.5])))
    # a collapsed row of poles: the boundary u = 0 is one point (the normal is undefined there)
    net = _net(rng, 7, 7)
    net[0] = net[0].mean(axis=0)
    bs("collapsed row (pole at u = 0)", net, (3, 3), (_clamped(3, [0.3, 0.301, 0.7]), _clamped(3, [0.3, 0.5, 0.7])))
    # curves: crowded, high degree, rational, Bézier 25, far away
    k = _crowded(3, [1e-6, 1e-6], -1.0, 3.0)
    pts = _net(rng, len(k) - 4, 1)[:, 0]
    out.append(_curve_case("curve, crowded 1e-6", BSplineCurve(pts, 3, k)))
    k = _clamped(9, [0.2, 0.5, 0.5, 0.5, 0.50001])
    out.append(_curve_case("curve, degree 9", BSplineCurve(_net(rng, len(k) - 10, 1)[:, 0], 9, k)))
    k = _crowded(2, [1e-4], 0.0, 10.0)
    out.append(_curve_case("curve, weights 1..1e4", BSplineCurve(_net(rng, len(k) - 3, 1)[:, 0], 2, k,
                                                                 10.0 ** rng.uniform(0, 4, len(k) - 3))))
    out.append(_curve_case("Bezier curve degree 25", BezierCurve(_net(rng, 26, 1, bump=0.2)[:, 0])))
    k = _crowded(3, [1e-5], 0.0, 1.0)
    out.append(_curve_case("curve, 1e6 from the origin",
                           BSplineCurve(_net(rng, len(k) - 4, 1)[:, 0] + [1e6, 1e6, -1e6], 3, k)))
    return out


#: the gallery modules whose entries are single lecture surfaces (the others build solids
#: and compounds: blends, fills, subdivision cages)
LECTURE_MODULES = ("synthetic", "analytic_surfaces", "swept")


def lecture_cases() -> list[Case]:
    """The gallery's lecture surfaces that have an exact B-spline or NURBS form, in that
    form (Bézier patches stay Bézier: OCCT evaluates them as ``Geom_BezierSurface``)."""
    out = []
    for e in entries():
        if e.build.__module__.rsplit(".", 1)[-1] not in LECTURE_MODULES or e.name.startswith(("sweep", "loft")):
            continue  # OCCT approximates sweeps and lofts: the case would be OCCT's approximation
        obj = e.build()
        if isinstance(obj, (BSplineSurface, BSplineCurve)):
            b, kind = obj, "curve" if isinstance(obj, BSplineCurve) else "surface"
        elif hasattr(obj, "to_bspline") or hasattr(obj, "to_nurbs"):
            kind, b = nurbs_of(obj, e.name)
        else:
            continue
        out.append(_curve_case(e.name, b) if kind == "curve" else _surface_case(e.name, b))
    return out


def step_cases(path, samples: int = FILE_SAMPLES) -> list[Case]:
    """The Bézier and B-spline faces of one STEP file (or of every STEP file of a folder),
    each over its own UV bounds."""
    path = Path(path)
    files = sorted(p for p in path.rglob("*") if p.suffix.lower() in (".step", ".stp")) if path.is_dir() else [path]
    out = []
    for f in files:
        faces = from_faces(_faces(import_step(f)))
        for i, face in enumerate(faces):
            s = face.surface
            if isinstance(s, BSplineSurface):
                out.append(_surface_case(f"{f.name} face {i}", s, samples, face.domain))
    return out


def _faces(shape):
    from ..occ.topo import faces_of

    return faces_of(shape)


def resolve(cases) -> list[Case]:
    """``cases`` as a list of :class:`Case`: ``"stress"``, ``"lecture"``, ``"corpus"``, a
    STEP path, or a list of surfmod B-spline/Bézier surfaces and curves."""
    if isinstance(cases, (str, Path)):
        name = str(cases)
        if name == "stress":
            return stress_cases()
        if name == "lecture":
            return lecture_cases()
        if name == "corpus":
            return step_cases(CORPUS)
        if Path(name).suffix.lower() in (".step", ".stp") or Path(name).is_dir():
            if not Path(name).exists():
                raise SurfmodError(f"cases: no such file {name!r}")
            return step_cases(name)
        raise SurfmodError(f"cases: expected 'stress', 'lecture', 'corpus', a STEP path or a list of surfaces, got {name!r}")
    try:
        items = list(cases)
    except TypeError:
        raise SurfmodError(f"cases: expected a name, a STEP path or a list, got {type(cases).__name__}") from None
    out = []
    for i, obj in enumerate(items):
        if isinstance(obj, Case):
            out.append(obj)
        elif isinstance(obj, BSplineSurface):
            out.append(_surface_case(f"surface {i}", obj))
        elif isinstance(obj, BSplineCurve):
            out.append(_curve_case(f"curve {i}", obj))
        else:
            raise SurfmodError(f"cases[{i}]: expected a surfmod B-spline or Bézier surface or curve, "
                               f"got {type(obj).__name__}")
    if not out:
        raise SurfmodError("cases: the list is empty")
    return out
