"""``sm.conformance``: an evaluator and OCCT against the 40-digit reference, case by case.

The error of an order is the largest, over the case's samples and the partials of that
order, of the distance to the reference divided by a scale.  Positions are measured
against the case's size (its largest position, or the extent of its samples if larger):
their round-off grows with the coordinates, wherever the origin is.  A partial is measured against its own size at
the sample (the largest partial of that order there), so a span where the derivatives are
small is not judged against the large ones of a crowded span nearby; never against less
than :data:`LOCAL_FLOOR` of the case's scale of that order (its largest partial of the
order, or the extent of its samples over the domain width to the order), so a partial
passing through zero is not judged against zero.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from tqdm import tqdm

from ..errors import MissingExtraError, SurfmodError
from . import adapters
from .cases import Case, resolve
from .reference import cached, reference

#: the stated limit: an evaluator within max(OCCT's error, LIMIT) of the reference conforms
LIMIT = 1e-12
#: a partial is measured against its own size at the sample, never less than this fraction
#: of its case's scale (positions against the case's scale: their error grows with the
#: coordinates, not with the distance from the origin)
LOCAL_FLOOR = 1e-3
#: the 40-digit reference costs about this much per sample and basis term ((p+1)(q+1) of a
#: surface) on one core
SECONDS_PER_TERM = 5e-4
#: default cap on the reference work of the uncached cases of one call (about 10 minutes;
#: the corpus needs 7e4)
MAX_TERMS = 1.2e6


class Row(NamedTuple):
    """One case at one order: the evaluator's worst relative error, OCCT's, who is right
    (which of the two is within :data:`LIMIT`: ``"both"``, ``"evaluator"``, ``"OCCT"`` or
    ``"neither"``), whether the evaluator conforms, and a note."""

    case: str
    order: int
    error: float
    occt_error: float
    right: str
    ok: bool
    note: str = ""


class Conformance(NamedTuple):
    """The table of :func:`conformance`: ``evaluator`` (its name), ``rows`` and ``passed``."""

    evaluator: str
    rows: list
    passed: bool
    limit: float = LIMIT

    def markdown(self) -> str:
        """The rows as a Markdown table, with a line saying how many conform."""
        lines = ["| case | order | evaluator | OCCT | right | conforms |", "|---|---:|---:|---:|---|---|"]
        for r in self.rows:
            lines.append(f"| {r.case} | {r.order} | {r.error:.1e} | {r.occt_error:.1e} | {r.right} | "
                         f"{'yes' if r.ok else '**no**'}{' — ' + r.note if r.note else ''} |")
        return "\n".join(lines) + "\n\n" + self.summary() + "\n"

    def summary(self) -> str:
        bad = sorted({r.case for r in self.rows if not r.ok})
        cases = len({r.case for r in self.rows})
        return (f"{self.evaluator}: {cases - len(bad)} of {cases} cases within max(OCCT, {self.limit:.0e}) of the "
                f"40-digit reference" + (f"; worse than OCCT on: {', '.join(bad)}" if bad else ""))


def _entries(case: Case, order: int):
    """Index tuples of the partials of exactly ``order`` in a case's partials array."""
    if case.is_curve:
        return [(order,)] if order <= 2 else []
    return [(k, order - k) for k in range(order + 1)]


def errors(case: Case, values: np.ndarray, ref: np.ndarray, order: int) -> float:
    """The relative error of ``values`` at ``order`` (see the module notes)."""
    idx = _entries(case, order)
    got = np.stack([values[(slice(None), *i)] for i in idx], axis=1)   # (N, E, 3)
    want = np.stack([ref[(slice(None), *i)] for i in idx], axis=1)
    size = np.linalg.norm(want, axis=-1).max(axis=1)                    # (N,)
    width = float(np.ptp(np.array(case.obj.domain, dtype=float).reshape(-1, 2), axis=1).max())
    positions = ref[(slice(None), *_entries(case, 0)[0])]
    extent = float(np.linalg.norm(np.ptp(positions, axis=0)))  # the object's size, not its distance
    scale = max(size.max(), extent / max(width, 1e-300) ** order, 1e-300)
    denominator = scale if order == 0 else np.maximum(size, LOCAL_FLOOR * scale)
    return float((np.linalg.norm(got - want, axis=-1).max(axis=1) / denominator).max())


def _judge(error: float, occt: float) -> tuple[str, bool]:
    """Who is right (within :data:`LIMIT`: ``"both"``, ``"evaluator"``, ``"OCCT"`` or
    ``"neither"``) and whether the evaluator conforms (within ``max(OCCT, LIMIT)``)."""
    mine, theirs = bool(error <= LIMIT), bool(occt <= LIMIT)  # NaN: not right
    right = {(True, True): "both", (True, False): "evaluator", (False, True): "OCCT"}.get((mine, theirs), "neither")
    return right, bool(error <= max(occt, LIMIT))


def conformance(evaluator, cases="stress", orders: int = 2, progress: bool = False,
                max_terms: float = MAX_TERMS) -> Conformance:
    """Hold ``evaluator`` against OCCT and the 40-digit reference on ``cases``.

    Parameters
    ----------
    evaluator : str or callable
        An adapter name (``"surfmod"``, the compiled basis kernel; ``"surfmod-patches"``,
        the compiled per-span Taylor patches; ``"surfmod-numpy"``; ``"occt"``;
        ``"geomdl"``; ``"splipy"``; ``"rhino3dm"``), ``"MODULE:FUNCTION"``, or a callable: with
        ``orders=0`` called as ``f(surface, u, v)`` returning positions ``(N, 3)``, else as
        ``f(surface, u, v, order)`` returning partials ``(N, order + 1, order + 1, 3)``,
        ``[..., k, l, :]`` = d^(k+l)S/du^k dv^l.  ``surface`` is the case as a surfmod
        ``BSplineSurface``/``BezierSurface`` (``control_points``, ``degree``, ``knots``,
        ``weights`` or None); ``u``, ``v`` are flat arrays.  A callable is held against
        the surface cases only.
    cases : str, path or list
        ``"stress"``, ``"lecture"``, ``"corpus"``, a STEP path, or a list of surfmod
        B-spline/Bézier surfaces and curves.
    orders : int
        The highest derivative order held: 0, 1 or 2.
    progress : bool
        Show a tqdm bar over the cases.
    max_terms : float
        Cap on the 40-digit work of the cases not in the cache (samples times basis
        terms), estimated before it starts.

    Returns
    -------
    Conformance
        One :class:`Row` per case and order with the evaluator's worst relative error,
        OCCT's and who is right; ``passed`` is False when the evaluator is worse than
        ``max(OCCT's error, 1e-12)`` on any row.

    Raises
    ------
    MissingExtraError
        The named adapter's library is not installed.
    SurfmodError
        Bad arguments, or a callable that raises, returns another shape or NaN (the
        message names the case).

    Examples
    --------
    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> s = sm.BezierSurface(net)
    >>> t = sm.conformance(lambda s, u, v: s.points(u, v), cases=[s], orders=0)
    >>> t.passed, t.rows[0].right
    (True, 'both')
    """
    if isinstance(orders, bool) or not isinstance(orders, (int, np.integer)) or not 0 <= orders <= 2:
        raise SurfmodError(f"orders: expected 0, 1 or 2, got {orders!r}")
    if isinstance(evaluator, str):
        reason = adapters.missing(evaluator)
        if reason:
            raise MissingExtraError(f"evaluator: {reason}")
        adapter = adapters.load(evaluator)
    elif callable(evaluator):
        adapter = adapters.wrap_callable(evaluator, getattr(evaluator, "__name__", "the callable"))
    else:
        raise SurfmodError(f"evaluator: expected an adapter name or a callable, got {type(evaluator).__name__}")
    held = [c for c in resolve(cases) if adapter.curves or not c.is_curve]
    if not held:
        raise SurfmodError("cases: no surface among them for a callable evaluator")
    work = sum(c.u.size * np.prod(np.atleast_1d(c.obj.degree) + 1) for c in held if not cached(c))
    if work > max_terms:
        raise SurfmodError(f"cases: their 40-digit reference would sum {work:.3g} basis terms (about "
                           f"{work * SECONDS_PER_TERM:.0f} s), above max_terms={max_terms:.3g}; raise it to allow them")
    rows = []
    for case in tqdm(held, desc="conformance", unit="case", disable=not progress):
        top = min(orders, adapter.curve_order if case.is_curve else adapter.max_order)
        ref = reference(case)
        occt = adapters.partials(adapters.ADAPTERS["occt"], case, top)
        try:
            mine, note = adapters.partials(adapter, case, top), ""
        except Exception as exc:  # a shipped library failing on one case is a row, not the end
            if adapters.ADAPTERS.get(adapter.name) is not adapter or isinstance(exc, MissingExtraError):
                raise
            mine, note = np.full_like(occt, np.nan), f"{adapter.name} raised {type(exc).__name__}: {exc}"
        for order in range(top + 1):
            err, occt_err = errors(case, mine, ref, order), errors(case, occt, ref, order)
            right, ok = _judge(err, occt_err)
            rows.append(Row(case.name, order, err, occt_err, right, ok, note))
    name = evaluator if isinstance(evaluator, str) else adapter.name
    return Conformance(name, rows, all(r.ok for r in rows))
