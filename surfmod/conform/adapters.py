"""Evaluators as the conformance suite calls them.

An adapter takes a case's object (a surfmod ``BSplineSurface``/``BezierSurface``, or a
``BSplineCurve``/``BezierCurve``), flat parameter arrays and an order, and returns the
partials: ``(N, K, K, 3)`` for a surface, ``[a, k, l]`` = d^(k+l)S/du^k dv^l at
``(u[a], v[a])``, or ``(N, K, 3)`` for a curve, ``K = order + 1``.  Each says up to which
order it evaluates (rhino3dm's surfaces give positions only).

A plain callable is wrapped by :func:`wrap_callable`: ``f(surface, u, v)`` for positions
(``orders=0``), ``f(surface, u, v, order)`` for partials; it is held against the surface
cases only (a callable has no curve signature).  What it returns is checked: the shape,
finite floats, and an exception becomes one :class:`~surfmod.errors.SurfmodError` naming
the case.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import Callable, NamedTuple

import numpy as np

from ..errors import SurfmodError
from ..eval import local
from ..eval.scattered import scattered
from ..interop.geomdl_io import to_geomdl
from ..interop.rhino_io import to_rhino
from ..interop.splipy_io import to_splipy


class Adapter(NamedTuple):
    """``name``; ``evaluate(obj, u, v, order)`` (``v`` None for a curve); the highest
    order it gives for surfaces and for curves; whether curve cases are held."""

    name: str
    evaluate: Callable
    max_order: int = 2
    curve_order: int = 2
    curves: bool = True


def _surfmod_compiled(obj, u, v, order):
    """surfmod's compiled basis-function kernel (what scattered points beyond a few
    thousand use), whatever the number of points."""
    from ..eval.kernels import binomials  # numba: compiled on first use, then from its disk cache
    from ..eval.scattered_compiled import scattered_compiled

    if v is None:
        return obj.derivatives(u, order)  # curves have one path, NumPy
    net = _net(obj)
    out = np.empty((u.size, order + 1, order + 1, 3))
    scattered_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, local.writable(u), local.writable(v),
                       int(order), net.rational, binomials(order), net.inv_u, net.inv_v, net.bucket_u, net.bucket_v,
                       out)
    return _placed(net, out)


def _net(obj):
    """The net surfmod's evaluators take: about its centre when it lies far from the origin
    (:func:`surfmod.eval.local.prepare`), as every path of surfmod evaluates it."""
    return local._centred(obj._local_net())


def _placed(net, out):
    """Partials of a centred net with the positions moved back in place."""
    local._add_origin(net, out[..., 0, 0, :] if out.ndim == 4 else out)
    return out


def _surfmod_patches(obj, u, v, order):
    """surfmod's compiled per-span Taylor patches (:mod:`surfmod.eval.patches`: many points
    on a small net of degree <= 3); the basis kernel where surfmod never uses them."""
    from ..eval import patches  # numba: compiled on first use, then from its disk cache

    if v is None:
        return _surfmod_compiled(obj, u, v, order)
    net = _net(obj)
    n, m = net.ctrl.shape[:2]
    if not patches.suits(net.p, net.q, n, m, net.ctrl[..., 3] if net.rational else None, (net.knots_u, net.knots_v)):
        return _surfmod_compiled(obj, u, v, order)  # where surfmod never uses patches
    table = patches.build_table(net)
    out = np.empty((u.size, 3) if order == 0 else (u.size, order + 1, order + 1, 3))
    kernel = patches.patch_positions_compiled if order == 0 else patches.patch_derivatives_compiled
    kernel(*patches.arguments(net, table, local.writable(u), local.writable(v), out))
    return _placed(net, out)


def _surfmod_numpy(obj, u, v, order):
    if v is None:
        return obj.derivatives(u, order)
    net = _net(obj)
    out = scattered(*net[:4], net.ctrl, net.rational, local.writable(u), local.writable(v), order)
    return _placed(net, out)


def _occt(obj, u, v, order):
    from ..occ import sample  # loads OCP
    from ..occ.arrays import xyz

    g = obj.geom()
    if v is None:
        out = sample.curve_d2(g, u)[:, : order + 1]
        # positions from Value, as for surfaces: D2's lose digits on high degrees (8e-8 at 25)
        out[:, 0] = [xyz(g.Value(float(t))) for t in u]
        return out
    return sample.surface_values_d2(g, u, v)[:, : order + 1, : order + 1]


def _geomdl(obj, u, v, order):
    g = to_geomdl(obj)
    if v is None:
        return np.array([g.derivatives(float(t), order) for t in u], dtype=float)
    return np.array([g.derivatives(float(a), float(b), order) for a, b in zip(u, v)], dtype=float)


def _splipy(obj, u, v, order):
    s = to_splipy(obj)
    # positions from evaluation: derivative(d=0) of a rational object is its homogeneous
    # numerator's, not the point (splipy 1.10)
    if v is None:
        return np.stack([s(u)] + [s.derivative(u, d=k) for k in range(1, order + 1)], axis=1)
    out = np.full((u.size, order + 1, order + 1, 3), np.nan)
    for k in range(order + 1):
        for l in range(order + 1 - k):  # point by point: tensor=False fails on rational surfaces (1.10)
            out[:, k, l] = [s(a, b) if k + l == 0 else s.derivative(a, b, d=(k, l)) for a, b in zip(u.tolist(), v.tolist())]
    return out


def _rhino3dm(obj, u, v, order):
    r = to_rhino(obj)
    if v is None:
        return np.array([[(p.X, p.Y, p.Z) for p in r.DerivativeAt(float(t), order)] for t in u], dtype=float)
    pts = [r.PointAt(float(a), float(b)) for a, b in zip(u, v)]
    return np.array([(p.X, p.Y, p.Z) for p in pts], dtype=float)[:, None, None]


ADAPTERS = {
    "surfmod": Adapter("surfmod", _surfmod_compiled),
    "surfmod-patches": Adapter("surfmod-patches", _surfmod_patches),
    "surfmod-numpy": Adapter("surfmod-numpy", _surfmod_numpy),
    "occt": Adapter("occt", _occt),
    "geomdl": Adapter("geomdl", _geomdl),
    "splipy": Adapter("splipy", _splipy),
    "rhino3dm": Adapter("rhino3dm", _rhino3dm, max_order=0),
}

#: the optional package each adapter needs, and the extra that brings it
OPTIONAL = {"geomdl": "interop", "splipy": "interop", "rhino3dm": "interop"}


def missing(name: str) -> str | None:
    """Why the named adapter cannot run here (its package is absent), or None."""
    package = OPTIONAL.get(name)
    if package is None:
        return None
    if importlib.util.find_spec(name) is None:
        return f"{name} is not installed: pip install \"surfmod[{package}]\""
    return None


def wrap_callable(f: Callable, name: str) -> Adapter:
    """A user's function as an :class:`Adapter` over the surface cases (see the module notes)."""

    def evaluate(obj, u, v, order):
        try:
            return f(obj, u, v) if order == 0 else f(obj, u, v, order)
        except Exception as exc:  # the user's code: any exception is bad input, said once
            raise SurfmodError(f"evaluator: {name} raised {type(exc).__name__}: {exc}") from None

    return Adapter(name, evaluate, curves=False)


def load(spec: str) -> Adapter:
    """An adapter by name, or ``MODULE:FUNCTION`` imported and wrapped."""
    if spec in ADAPTERS:
        return ADAPTERS[spec]
    if ":" not in spec:
        raise SurfmodError(f"evaluator: unknown adapter {spec!r}; expected one of "
                           f"{', '.join(ADAPTERS)} or MODULE:FUNCTION")
    module, _, function = spec.partition(":")
    try:
        f = getattr(importlib.import_module(module), function)
    except (ImportError, AttributeError) as exc:
        raise SurfmodError(f"evaluator: cannot load {spec!r}: {exc}") from None
    if not callable(f):
        raise SurfmodError(f"evaluator: {spec!r} is not callable")
    return wrap_callable(f, spec)


def partials(adapter: Adapter, case, order: int) -> np.ndarray:
    """The adapter's partials of ``case`` to ``order``, checked: ``(N, K, K, 3)`` or, for
    a curve, ``(N, K, 3)``; positions only (``order == 0``) may come as ``(N, 3)``."""
    n, kk = case.u.size, order + 1
    out = adapter.evaluate(case.obj, case.u.copy(), None if case.v is None else case.v.copy(), order)
    try:
        arr = np.asarray(out, dtype=float)
    except (TypeError, ValueError):
        raise SurfmodError(f"evaluator: {adapter.name} returned {type(out).__name__}, not an array of "
                           f"floats, on case {case.name!r}") from None
    want = (n, kk, 3) if case.is_curve else (n, kk, kk, 3)
    if order == 0 and arr.shape == (n, 3):
        arr = arr.reshape(want)
    if arr.shape != want:
        expected = f"({n}, 3)" if order == 0 else str(want)
        raise SurfmodError(f"evaluator: {adapter.name} returned shape {arr.shape} on case {case.name!r}, "
                           f"expected {expected}")
    mask = np.ones(want[1:-1], bool)
    if not case.is_curve:
        mask = np.add.outer(np.arange(kk), np.arange(kk)) <= order
    if not np.all(np.isfinite(arr[:, mask])):
        raise SurfmodError(f"evaluator: {adapter.name} returned NaN or infinity on case {case.name!r}")
    return arr
