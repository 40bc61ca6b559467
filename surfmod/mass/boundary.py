"""Stage three of the mass pipeline (:mod:`surfmod.mass`): the boundary pieces, Gauss nodes on
a face's p-curves (:func:`boundaries`), the outer integral of Green's theorem.

A face's p-curves are one table (:class:`PcurveTable`) evaluated from their data at
``(record, parameter)`` pairs in one pass per kind, not one per p-curve.
See :doc:`/guide/uses` (section "How a face is integrated").
"""

from __future__ import annotations

import numpy as np

from ..eval.basis import basis_derivatives
from .breaks import ANGULAR_PIECE, spline_breaks
from .rules import gauss

#: curved p-curves are cut into at least this many pieces before Gauss
PIECES = 4

_KINDS = {"line": 0, "circle": 1, "bspline": 2}

#: np.linspace(0, 1, PIECES + 1), made once
PIECE_FRACTIONS = np.linspace(0.0, 1.0, PIECES + 1)
_FRACTION_CACHE: dict = {}


def _fractions(pieces: int) -> np.ndarray:
    """``np.linspace(0, 1, pieces + 1)`` (cached: the same few counts every call)."""
    if pieces not in _FRACTION_CACHE:
        _FRACTION_CACHE[pieces] = np.linspace(0.0, 1.0, pieces + 1)
    return _FRACTION_CACHE[pieces]


def piece_spans(breaks: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = gauss(order)
    a, b = breaks[:-1, None], breaks[1:, None]
    return ((a + b) / 2 + (b - a) / 2 * x).ravel(), ((b - a) / 2 * w).ravel()


def pcurve_d1(rec: dict, t: np.ndarray) -> np.ndarray:
    """``(N, 4)``: ``u, v, du/dt, dv/dt`` of a p-curve record at parameters ``t``."""
    t = np.asarray(t, dtype=float).ravel()
    return PcurveTable([rec]).d1(np.zeros(t.size, int), t)


def taylor_pieces(records: list) -> None:
    """Set ``rec["taylor"]`` and ``rec["breaks"]`` (:func:`~surfmod.mass.breaks.spline_breaks`) on
    every B-spline p-curve record that lacks them.  ``rec["taylor"]`` is the p-curve as one
    polynomial per knot span: ``(starts (S,), centres (S,), coefficients (S, p+1, dim))``
    with ``C(t) = Σ_k c_k (t - centre)^k`` in homogeneous coordinates ``(w u, w v, w)``
    (``(u, v)`` when polynomial); beyond the ends the first and last spans continue, as
    OCCT evaluates.  One basis evaluation per degree serves all of them: their knot vectors and control points
    are laid end to end, and each span's basis reads only its own curve's knots
    (``knots[span - p + 1 .. span + p]``), so one call serves all.

    >>> import build123d as bd
    >>> from surfmod.occ.pcurves import face_pcurves
    >>> recs = [r for r in face_pcurves(bd.Face(bd.Wire([bd.Spline((0, 0), (1, 1), (2, 0), (1, -1)),
    ...         bd.Edge.make_line((1, -1), (0, 0))])).wrapped) if r["kind"] == "bspline"]
    >>> taylor_pieces(recs); starts, centres, coef = recs[0]["taylor"]
    >>> coef.shape[1:] == (recs[0]["degree"] + 1, 2)
    True
    """
    spline_breaks([rec for rec in records if rec["kind"] == "bspline" and "breaks" not in rec])
    groups: dict = {}
    for rec in records:
        if rec["kind"] == "bspline" and "taylor" not in rec:
            groups.setdefault(rec["degree"], []).append(rec)
    for p, group in groups.items():
        # knots and control points laid end to end: the spans of every curve are the
        # indices i in [p, n - 1] of its own knots with k[i] < k[i + 1] (its knots run on
        # past n - 1, so k[i + 1] is always its own), centred at (k[i] + k[i + 1]) / 2
        nk = np.array([len(rec["knots"]) for rec in group])
        nc = np.array([len(rec["points"]) for rec in group])
        all_knots = np.concatenate([rec["knots"] for rec in group])
        pts = np.concatenate([rec["points"][:, :2] for rec in group])
        w = np.concatenate([np.ones(n) if rec["weights"] is None else rec["weights"] for rec, n in zip(group, nc)])
        all_ctrl = np.column_stack([pts * w[:, None], w])  # homogeneous (w u, w v, w)
        k_off, c_off = np.cumsum(nk) - nk, np.cumsum(nc) - nc
        owner = np.repeat(np.arange(len(group)), nk)
        local = np.arange(len(all_knots)) - k_off[owner]
        inside = (local >= p) & (local <= nc[owner] - 1)
        inside[inside] &= all_knots[np.flatnonzero(inside) + 1] > all_knots[inside]
        span = np.flatnonzero(inside)
        starts, ends = all_knots[span], all_knots[span + 1]
        mid = (starts + ends) / 2  # expanded about each span's middle: keeps high degrees accurate
        rec_of = owner[span]
        first = span - k_off[rec_of] - p + c_off[rec_of]
        coef = _span_derivatives(all_knots, p, span, mid, all_ctrl[first[:, None] + np.arange(p + 1)])
        cuts = np.searchsorted(rec_of, np.arange(len(group) + 1)).tolist()
        planar = np.ascontiguousarray(coef[:, :, :2])  # polynomial records: (u, v) only, one copy for all
        for i, rec in enumerate(group):
            lo, hi = cuts[i], cuts[i + 1]
            rec["taylor"] = (starts[lo:hi], mid[lo:hi], coef[lo:hi] if rec["weights"] is not None else planar[lo:hi])


def _span_derivatives(knots, p: int, span, mid, poles) -> np.ndarray:
    """``(S, p + 1, dim)``: ``C^(k)(mid) / k!`` of each span's curve (its ``p + 1`` poles
    ``(S, p + 1, dim)``), from the span's derivative poles (Bohm: ``(p - k + 1) (Q[r + 1]
    - Q[r]) / (knot difference)``, The NURBS Book eq. 3.8) and the positive basis of
    degree ``p - k``.  The sum of basis derivatives times poles cancels where spans are
    short and poles far apart from their differences (a p-curve on a face whose knots
    crowd into spans of 1e-9 lost 2e-10 of its derivative); differences of neighbouring
    poles do not."""
    out = np.empty(poles.shape)
    q, factorial = poles, 1.0
    for k in range(p + 1):
        if k:
            r = np.arange(p + 1 - k)
            gap = knots[span[:, None] + r + 1] - knots[span[:, None] - p + r + k]
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(gap > 0, (p - k + 1) / gap, 0.0)
            q = (q[:, 1:] - q[:, :-1]) * scale[:, :, None]
            factorial *= k
        basis = basis_derivatives(knots[k:], p - k, span - k, mid, 0)[:, 0, :]  # (S, p - k + 1)
        out[:, k] = np.einsum("sr,srd->sd", basis, q) / factorial
    return out


def pcurve_crossings(rec: dict, cuts: np.ndarray, lines_u: np.ndarray, lines_v: np.ndarray, per_piece: int = 8) -> np.ndarray:
    """Parameters where a p-curve crosses the lines ``u = c`` and ``v = c``: exact on
    straight and circular p-curves, else :func:`_table_crossings` on its pieces ``cuts``."""
    if not len(lines_u) and not len(lines_v):
        return np.zeros(0)
    f, l = cuts[0], cuts[-1]
    coord = np.concatenate([np.zeros(len(lines_u), int), np.ones(len(lines_v), int)])
    lines = np.concatenate([lines_u, lines_v])
    if rec["kind"] == "line":
        d = rec["direction"][coord]
        ok = d != 0.0
        t = (lines[ok] - rec["origin"][coord[ok]]) / d[ok]
        return t[(t > f) & (t < l)]
    if rec["kind"] == "circle":
        # centre + r (cos t x + sin t y) = line: A cos t + B sin t = C, t = phi ± acos(C / R)
        r = rec["radius"]
        A, B, C = r * rec["x"][coord], r * rec["y"][coord], lines - rec["centre"][coord]
        R = np.hypot(A, B)
        ok = np.abs(C) < R
        phi, half = np.arctan2(B[ok], A[ok]), np.arccos(C[ok] / R[ok])
        base = np.concatenate([phi + half, phi - half])
        turns = np.arange(np.floor((f - base.max()) / (2 * np.pi)), np.ceil((l - base.min()) / (2 * np.pi)) + 1)
        t = (base[:, None] + 2 * np.pi * turns[None, :]).ravel()
        return t[(t > f) & (t < l)]
    pieces = len(cuts) - 1
    x, _ = _table_crossings(PcurveTable([rec]), np.zeros(pieces, int), cuts[:-1], cuts[1:], np.full(pieces, abs(l - f)),
                            np.tile(lines, (pieces, 1)), np.tile(coord, (pieces, 1)), per_piece)
    return x


class PcurveTable:
    """The p-curves of one face as arrays, evaluated at ``(record, parameter)`` pairs in
    one NumPy pass per kind (:meth:`d1`), equal to :func:`pcurve_d1` record by record.

    B-spline records need their ``"taylor"`` pieces (:func:`taylor_pieces`); their spans
    are laid end to end and found for all nodes by one ``searchsorted`` on the keys
    ``record + 1j * span start`` (NumPy orders complex numbers lexicographically, so each
    record's spans stay apart without shifting parameters).

    >>> import build123d as bd
    >>> from surfmod.occ.pcurves import face_pcurves
    >>> recs = face_pcurves(bd.Face(bd.Wire([bd.Spline((0, 0), (1, 1), (2, 0), (1, -1)),
    ...         bd.Edge.make_line((1, -1), (0, 0))])).wrapped)
    >>> taylor_pieces(recs)
    >>> t = np.array([sum(r["range"]) / 2 for r in recs])
    >>> both = PcurveTable(recs).d1(np.arange(len(recs)), t)
    >>> bool(np.array_equal(both, np.vstack([pcurve_d1(r, t[i:i + 1]) for i, r in enumerate(recs)])))
    True
    """

    def __init__(self, records: list):
        self.records = records
        n = len(records)
        self.kind = np.array([_KINDS.get(rec["kind"], 3) for rec in records], dtype=int)
        self.present = set(self.kind.tolist())
        if 0 in self.present:
            self.origin, self.direction = np.zeros((n, 2)), np.zeros((n, 2))
        if 1 in self.present:
            self.centre, self.ax, self.ay, self.radius = np.zeros((n, 2)), np.zeros((n, 2)), np.zeros((n, 2)), np.zeros(n)
        # per record: a B-spline without weights (a polynomial p-curve)
        self.polynomial = np.zeros(n, bool)
        splines = []
        for i, rec in enumerate(records):
            kind = self.kind[i]
            if kind == 0:
                self.origin[i], self.direction[i] = rec["origin"], rec["direction"]
            elif kind == 1:
                self.centre[i], self.ax[i], self.ay[i], self.radius[i] = rec["centre"], rec["x"], rec["y"], rec["radius"]
            elif kind == 2:
                if "taylor" not in rec:
                    taylor_pieces([rec])
                splines.append((i, rec))
                self.polynomial[i] = rec["weights"] is None
        if splines:
            self._spline_table(splines, n)

    def _spline_table(self, splines, n):
        # rational records in homogeneous (w u, w v, w), polynomial ones as (u, v) -- or
        # as (u, v, 1) beside a rational one: dividing by w = 1 leaves them bit for bit
        self.rational = any(rec["weights"] is not None for _, rec in splines)
        dim = 3 if self.rational else 2
        top = max(rec["taylor"][2].shape[1] for _, rec in splines)
        index = np.array([i for i, _ in splines])
        lens = np.array([len(rec["taylor"][0]) for _, rec in splines])
        self.first, self.last = np.zeros(n, int), np.zeros(n, int)
        ends = np.cumsum(lens)
        self.first[index], self.last[index] = ends - lens, ends - 1
        self.keys = np.repeat(index, lens) + 1j * np.concatenate([rec["taylor"][0] for _, rec in splines])
        self.centres = np.concatenate([rec["taylor"][1] for _, rec in splines])
        # higher powers padded with zeros; the records of one coefficient shape in one assignment
        self.coef = np.zeros((int(ends[-1]), top, dim))
        shapes: dict = {}
        for k, (_, rec) in enumerate(splines):
            shapes.setdefault(rec["taylor"][2].shape[1:], []).append(k)
        for (width, cdim), members in shapes.items():
            m_lens = lens[members]  # the members' span rows, laid end to end
            rows = np.arange(m_lens.sum()) + np.repeat(ends[members] - lens[members] - (np.cumsum(m_lens) - m_lens), m_lens)
            self.coef[rows, :width, :cdim] = np.concatenate([splines[k][1]["taylor"][2] for k in members])
            if cdim < dim:
                self.coef[rows, 0, 2] = 1.0
        self.coef_by_power = np.ascontiguousarray(self.coef.transpose(1, 0, 2))  # (p+1, S, dim)

    def subset(self, rows: np.ndarray) -> "PcurveTable":
        """The table of the records ``rows`` (in that order), taken from this one's arrays:
        the same values :class:`PcurveTable` builds from those records (a table with a
        rational record keeps the homogeneous form, whose division by ``w = 1`` leaves
        polynomial records bit for bit)."""
        rows = np.asarray(rows, int)
        out = PcurveTable.__new__(PcurveTable)
        out.records = [self.records[i] for i in rows]
        out.kind = self.kind[rows]
        out.present = set(out.kind.tolist())
        out.polynomial = self.polynomial[rows]
        for name in ("origin", "direction", "centre", "ax", "ay", "radius"):
            if hasattr(self, name):
                setattr(out, name, getattr(self, name)[rows])
        spline = np.flatnonzero(out.kind == 2)
        if len(spline):
            old = rows[spline]
            lens = self.last[old] - self.first[old] + 1
            ends = np.cumsum(lens)
            spans = np.arange(ends[-1]) + np.repeat(self.first[old] - (ends - lens), lens)
            out.first, out.last = np.zeros(len(rows), int), np.zeros(len(rows), int)
            out.first[spline], out.last[spline] = ends - lens, ends - 1
            out.keys = np.repeat(spline, lens) + 1j * self.keys.imag[spans]
            out.centres, out.coef = self.centres[spans], self.coef[spans]
            out.coef_by_power = self.coef_by_power[:, spans]
            out.rational = self.rational
        return out

    def d1(self, which: np.ndarray, t: np.ndarray, span: np.ndarray | None = None) -> np.ndarray:
        """``(N, 4)``: ``u, v, du/dt, dv/dt`` of record ``which[n]`` at ``t[n]``; ``span``
        (optional, per row): the B-spline rows' span polynomial when the caller knows it
        (:meth:`span_of`), ``-1`` where not."""
        out = np.empty((len(t), 4))
        if len(self.present) == 1:
            masks = {next(iter(self.present)): slice(None)}
        else:
            kind = self.kind[which]
            masks = {k: kind == k for k in self.present}
        for k, m in masks.items():
            r, tt = which[m], t[m]
            if k == 0:
                d = self.direction[r]
                out[m, :2] = self.origin[r] + tt[:, None] * d
                out[m, 2:] = d
            elif k == 1:
                c, s = np.cos(tt)[:, None], np.sin(tt)[:, None]
                rad, x, y = self.radius[r][:, None], self.ax[r], self.ay[r]
                out[m, :2] = self.centre[r] + rad * (c * x + s * y)
                out[m, 2:] = rad * (c * y - s * x)
            elif k == 2:
                out[m] = self._spline_d1(r, tt, None if span is None else span[m])
            else:
                from ..occ.pcurves import adaptor_d1

                rows = np.flatnonzero(m) if isinstance(m, np.ndarray) else np.arange(len(t))
                for i in np.unique(r):
                    sel = rows[which[rows] == i]
                    out[sel] = adaptor_d1(self.records[i]["adaptor"], t[sel])
        return out

    def span_of(self, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Row of the span polynomial of B-spline record ``r[n]`` at ``t[n]``."""
        return np.clip(np.searchsorted(self.keys, r + 1j * t, side="right") - 1, self.first[r], self.last[r])

    def _spline_d1(self, r: np.ndarray, t: np.ndarray, j: np.ndarray | None = None) -> np.ndarray:
        if j is None:
            j = self.span_of(r, t)
        elif (unknown := j < 0).any():
            j = j.copy()
            j[unknown] = self.span_of(r[unknown], t[unknown])
        dt = (t - self.centres[j])[:, None]
        c = self.coef_by_power[:, j]  # (p+1, N, dim): each power's rows contiguous
        val, der = c[-1], np.zeros_like(c[-1])
        for k in range(c.shape[0] - 2, -1, -1):  # Horner for the value and its derivative
            der = der * dt + val
            val = val * dt + c[k]
        out = np.empty((len(t), 4))
        if not self.rational:
            out[:, :2], out[:, 2:] = val, der
        else:
            out[:, :2] = val[:, :2] / val[:, 2:]
            out[:, 2:] = (der[:, :2] - out[:, :2] * der[:, 2:]) / val[:, 2:]
        return out


def _table_crossings(table: PcurveTable, owner, a, b, scale, lines, coord, per_piece: int = 8):
    """:func:`pcurve_crossings` of curved p-curves at once: pieces ``[a, b]`` of records ``owner``
    (indices into ``table``; ``scale`` per piece: its record's parameter length, for the
    Newton tolerance) against per piece the lines ``lines[piece]`` of coordinate
    ``coord[piece]`` (``(pieces, L)``, NaN-padded: each face has its own), one sampling and
    one evaluation per Newton step for all of them.  Returns the crossing parameters and
    their records."""
    t = (a[:, None] + (b - a)[:, None] * _fractions(per_piece)).ravel()
    which = np.repeat(owner, per_piece + 1)
    piece = np.repeat(np.arange(len(owner)), per_piece + 1)
    vals = table.d1(which, t)
    s = np.take_along_axis(vals, coord[piece], axis=1) - lines[piece]  # (T, L); NaN never changes sign
    # sign changes inside one piece only (consecutive pieces of a record share their ends)
    same = np.ones(len(t) - 1, bool)
    same[per_piece :: per_piece + 1] = False
    i, j = np.nonzero((s[:-1] * s[1:] < 0) & same[:, None])
    if not len(i):
        return np.zeros(0), np.zeros(0, int)
    lo, hi, rec = t[i], t[i + 1], which[i]
    c, cj = lines[piece[i], j], coord[piece[i], j]
    x = lo + (hi - lo) * s[i, j] / (s[i, j] - s[i + 1, j])
    tol = 1e-15 * np.maximum(1.0, scale[piece[i]])
    active = np.arange(len(x))
    for _ in range(6):  # each crossing stops once its own Newton step is at round-off
        q = table.d1(rec[active], x[active])
        k = np.arange(len(active))
        d = q[k, 2 + cj[active]]
        step = np.divide(q[k, cj[active]] - c[active], d, out=np.zeros(len(active)), where=d != 0.0)
        x[active] = np.clip(x[active] - step, lo[active], hi[active])
        active = active[np.abs(step) > tol[active]]
        if not len(active):
            break
    return x, rec


def _long_pieces(table: PcurveTable, owner, a, b, directions) -> np.ndarray:
    """Which pieces ``[a, b]`` of records ``owner`` may run more than an eighth turn
    (``ANGULAR_PIECE``) along their angular directions (``directions``: ``(pieces, 2)``
    booleans): a bound from the span's own polynomial, ``2 Σ_k |c_k| r^k`` (``r`` the reach
    from its centre); every piece of a rational or non-spline p-curve counts as long."""
    long = np.ones(len(owner), bool)
    spline = table.kind[owner] == 2
    spline[spline] = table.polynomial[owner[spline]]
    if not spline.any():
        return long
    r_own, lo, hi = owner[spline], a[spline], b[spline]
    j = table.span_of(r_own, (lo + hi) / 2)
    reach = np.maximum(np.abs(lo - table.centres[j]), np.abs(hi - table.centres[j]))
    c = np.abs(table.coef[j][:, 1:, :2])  # (P, top - 1, 2): the non-constant terms
    powers = reach[:, None] ** np.arange(1, c.shape[1] + 1)
    extent = 2 * np.einsum("pk,pkd->pd", powers, c)
    long[spline] = np.any((extent > ANGULAR_PIECE) & directions[spline], axis=1)
    return long


def _padded(rows: list, n: int, fill) -> np.ndarray:
    out = np.full((n, max([len(r) for r in rows] + [0])), fill)
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


def boundaries(faces: list, table: PcurveTable | None = None) -> list:
    """Gauss nodes on the p-curves of many faces in one pass: per face ``(P (N, 2), dP (N,
    2), weights (N,), exact)``, the weights signed by each edge's orientation in its face.

    ``faces``: per face ``(pcurves, orders, exacts, lines_u, lines_v, angular)`` -- per
    p-curve the Gauss order of its pieces and whether that rule is exact; the lines
    ``u = c``, ``v = c`` the p-curves are cut at (the surface's breaks); per direction
    whether those are only the eighth turns of an analytic angle (no knot: the integrands
    are smooth across them; they keep Gauss within an eighth turn, so a B-spline piece that
    cannot reach that far (:func:`_long_pieces`) is not searched).  ``table``: the
    :class:`PcurveTable` of all their p-curves laid end to end, when already built.  Each
    record also gets ``"ends"``, its points at the ends of its range.

    The records of all faces are laid end to end: their cuts, crossings, Newton steps and
    Gauss nodes are found with a few array passes for the whole part, not per face.

    >>> import build123d as bd
    >>> from surfmod.occ.pcurves import face_pcurves
    >>> disc = face_pcurves(bd.Face(bd.Wire.make_circle(1.0)).wrapped)
    >>> ((P, dP, w, exact),) = boundaries([(disc, [12], [False], [], [], (False, False))])
    >>> P.shape, round(float(np.sum(w * P[:, 0] * dP[:, 1])), 12), exact  # ∮ u dv = area
    ((48, 2), 3.14159265359, False)
    """
    records = [rec for face in faces for rec in face[0]]
    counts = [len(face[0]) for face in faces]
    face_of = np.repeat(np.arange(len(faces)), counts)
    if not records:
        return [(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), True) for _ in faces]
    table = PcurveTable(records) if table is None else table
    orders = np.concatenate([np.asarray(face[1], int) for face in faces])
    exacts = np.concatenate([np.asarray(face[2], bool) for face in faces])
    ranges = np.array([rec["range"] for rec in records])
    f_all, l_all = ranges[:, 0], ranges[:, 1]
    live = l_all > f_all
    # cuts of every live record, as one array sorted by (record, parameter): complex keys
    # record + 1j * t sort lexicographically, so np.unique merges each record's own breaks
    # lines: their ends; circles (one smooth interval) and curved p-curves: PIECES equal
    # pieces, the curved ones also cut at their own breaks (knots) inside the range
    idx = np.flatnonzero(live)
    straight = table.kind[idx] == 0
    frac = PIECE_FRACTIONS
    f, l = f_all[idx, None], l_all[idx, None]
    even = f + (l - f) * frac
    even[:, -1] = l[:, 0]  # the end itself, as np.linspace gives it
    even[straight, 1:-1] = np.nan  # a line's pieces: just its ends
    curved = idx[table.kind[idx] >= 2]
    breaks = [records[i]["breaks"] for i in curved]
    b_rec = np.repeat(curved, [len(b) for b in breaks])
    b_val = np.concatenate(breaks) if breaks else np.zeros(0)
    inside = (b_val >= f_all[b_rec]) & (b_val <= l_all[b_rec])
    # a curved p-curve whose own breaks already cut it into pieces of at most 1/PIECES of
    # its range needs no equal pieces on top (they would only add nodes)
    fine = np.zeros(len(records), bool)
    if len(curved):
        longest = np.zeros(len(records))
        ends = np.concatenate([b_rec[inside] + 1j * b_val[inside], curved + 1j * f_all[curved], curved + 1j * l_all[curved]])
        ends = np.unique(ends)
        same = ends.real[1:] == ends.real[:-1]
        np.maximum.at(longest, ends.real[1:][same].astype(int), np.diff(ends.imag)[same])
        fine[curved] = longest[curved] <= (l_all[curved] - f_all[curved]) / PIECES * (1 + 1e-12)
    even[fine[idx], 1:-1] = np.nan
    keys = np.concatenate([(idx[:, None] + 1j * even).ravel(), b_rec[inside] + 1j * b_val[inside]])
    cuts = np.unique(keys[~np.isnan(keys.imag)])
    lines_u = [np.asarray(face[3], float) for face in faces]
    lines_v = [np.asarray(face[4], float) for face in faces]
    angular = np.array([face[5] for face in faces], bool).reshape(len(faces), 2)
    if any(len(u) or len(v) for u, v in zip(lines_u, lines_v)):
        cuts = _cut_at_lines(table, cuts, face_of, lines_u, lines_v, angular, ranges)
    # Gauss nodes of every piece of every p-curve, in record order, one order at a time
    rec_of, val = cuts.real.astype(int), cuts.imag
    inner = rec_of[:-1] == rec_of[1:]
    owner, a, b = rec_of[:-1][inner], val[:-1][inner], val[1:][inner]
    count = orders[owner]
    start = np.concatenate([[0], np.cumsum(count)[:-1]])
    t, w = np.empty(count.sum()), np.empty(count.sum())
    for m in np.unique(count):
        x, gw = gauss(int(m))
        sel = np.flatnonzero(count == m)
        at = (start[sel][:, None] + np.arange(m)).ravel()
        aa, bb = a[sel, None], b[sel, None]
        t[at] = ((aa + bb) / 2 + (bb - aa) / 2 * x).ravel()
        w[at] = ((bb - aa) / 2 * gw).ravel()
    which = np.repeat(owner, count)
    live_idx = np.flatnonzero(live)
    # a piece lies within one span of its B-spline (the cuts hold its knots): the span of
    # its middle serves all its nodes, one search per piece instead of per node
    piece_span = np.full(len(owner), -1)
    spline = table.kind[owner] == 2
    if spline.any():
        piece_span[spline] = table.span_of(owner[spline], (a[spline] + b[spline]) / 2)
    span = np.concatenate([np.repeat(piece_span, count), np.full(2 * len(live_idx), -1)])
    q = table.d1(np.concatenate([which, np.repeat(live_idx, 2)]), np.concatenate([t, ranges[live_idx].ravel()]), span)
    n = len(t)
    for k, i in enumerate(live_idx):  # for _largest_gap, from the same evaluation
        records[i]["ends"] = q[n + 2 * k : n + 2 * k + 2, :2]
    sign = np.array([rec["sign"] for rec in records])
    w = sign[which] * w
    node_face = face_of[which]
    bounds = np.searchsorted(node_face, np.arange(len(faces) + 1))
    # per face: every rule of its live p-curves exact (records are laid out face by face)
    inexact = np.zeros(len(faces), int)
    np.add.at(inexact, face_of, ~exacts & live)
    P, dP = q[:, :2], q[:, 2:]
    return [(P[lo:hi], dP[lo:hi], w[lo:hi], not bad) for lo, hi, bad in zip(bounds[:-1], bounds[1:], inexact.tolist())]


def _cut_at_lines(table, cuts, face_of, lines_u, lines_v, angular, ranges):
    """``cuts`` (complex keys record + 1j t) with the crossings of every record with its
    face's lines added (closed form for lines and circles, sampling and Newton for the
    others; see :func:`boundaries`)."""
    records = table.records
    rec_of, val = cuts.real.astype(int), cuts.imag
    extra_keys = []
    for i in np.unique(rec_of[table.kind[rec_of] < 2]):  # straight and circular: closed form
        k = face_of[i]
        if len(lines_u[k]) or len(lines_v[k]):
            x = pcurve_crossings(records[i], val[rec_of == i], lines_u[k], lines_v[k])
            extra_keys.append(i + 1j * x)
    inner = (rec_of[:-1] == rec_of[1:]) & (table.kind[rec_of[:-1]] >= 2)
    owner, a, b = rec_of[:-1][inner], val[:-1][inner], val[1:][inner]
    face_has_lines = np.array([len(u) + len(v) > 0 for u, v in zip(lines_u, lines_v)], bool)
    has_lines = face_has_lines[face_of[owner]]
    owner, a, b = owner[has_lines], a[has_lines], b[has_lines]
    if len(owner):
        scale = np.abs(ranges[owner, 1] - ranges[owner, 0])
        piece_face = face_of[owner]
        n_faces = len(lines_u)
        for turn in (False, True):  # knot lines on every piece, eighth turns on long ones
            rows, coords = [], []
            for k in range(n_faces):
                u = lines_u[k] if angular[k, 0] == turn else np.zeros(0)
                v = lines_v[k] if angular[k, 1] == turn else np.zeros(0)
                rows.append(np.concatenate([u, v]))
                coords.append(np.concatenate([np.zeros(len(u), int), np.ones(len(v), int)]))
            if not any(len(r) for r in rows):
                continue
            lines, coord = _padded(rows, n_faces, np.nan), _padded(coords, n_faces, 0).astype(int)
            sel = np.array([len(r) > 0 for r in rows], bool)[piece_face]
            if turn:
                sel[sel] = _long_pieces(table, owner[sel], a[sel], b[sel], angular[piece_face[sel]])
            if sel.any():
                pf = piece_face[sel]
                x, rec = _table_crossings(table, owner[sel], a[sel], b[sel], scale[sel], lines[pf], coord[pf])
                extra_keys.append(rec + 1j * x)
    extra = np.concatenate(extra_keys) if extra_keys else np.zeros(0, complex)
    if not extra.size:
        return cuts
    merged = np.unique(np.concatenate([cuts, extra]))
    # within a record that gained crossings, drop cuts closer than 1e-13 of its length
    rec_m, val_m = merged.real.astype(int), merged.imag
    gained = np.zeros(len(records), bool)
    gained[extra.real.astype(int)] = True
    tol = 1e-13 * np.maximum(1.0, ranges[rec_m, 1] - ranges[rec_m, 0])
    close = (rec_m[1:] == rec_m[:-1]) & (np.diff(val_m) <= tol[1:]) & gained[rec_m[1:]]
    return merged[np.concatenate([[True], ~close])]
