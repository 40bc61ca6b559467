"""Stage one of the mass pipeline (:mod:`surfmod.mass`): Gauss–Legendre rules (cached), the
orders exact for polynomial directions, and the inner integrals of Green's theorem, node
by node (:func:`inner_nodes`) or on one Chebyshev interpolation grid per cell
(:func:`grids_nodes`).  See :doc:`/guide/uses` (section "How a face is integrated").
"""

from __future__ import annotations

import numpy as np

_GAUSS: dict = {}


def gauss(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on ``[-1, 1]`` (cached).

    >>> x, w = gauss(3)
    >>> round(float(w.sum()), 15), round(float((w * x**4).sum()), 15)
    (2.0, 0.4)
    """
    if order not in _GAUSS:
        _GAUSS[order] = np.polynomial.legendre.leggauss(order)
    return _GAUSS[order]


def exact_order(degree: int) -> int:
    """Gauss nodes per span that integrate the mass integrands exactly on a direction in
    which the surface is a polynomial of ``degree`` (integrand degree ``5 degree``).

    >>> exact_order(1), exact_order(3), exact_order(5)
    (3, 8, 13)
    """
    return (5 * degree + 2) // 2


def chebyshev(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` Chebyshev points (first kind: inside ``(-1, 1)``, never on a span's end, where
    a degree-1 spline's derivatives jump), their barycentric weights, and the Chebyshev
    coefficients of their Lagrange basis, ``ℓ_j = Σ_m A[j, m] T_m`` (cached).
    Interpolation there is well conditioned at any degree.

    >>> x, bw, A = chebyshev(3)
    >>> x.round(12).tolist(), round(float(antiderivative_weights(np.array([1.0]), 3)[0] @ x**2), 14)
    ([0.866025403784, 0.0, -0.866025403784], 0.66666666666667)
    """
    key = ("chebyshev", n)
    if key not in _GAUSS:
        theta = (2 * np.arange(n) + 1) * np.pi / (2 * n)
        bw = np.where(np.arange(n) % 2 == 0, 1.0, -1.0) * np.sin(theta)
        # discrete orthogonality of T_m at these points: ℓ_j = (1/n) T_0 + (2/n) Σ_{m>0} T_m(x_j) T_m
        A = 2.0 / n * np.cos(np.outer(theta, np.arange(n)))
        A[:, 0] /= 2
        _GAUSS[key] = (np.cos(theta), bw, A)
        _GAUSS[("span integral", n)] = antiderivative_weights(np.ones(1), n)[0]
    return _GAUSS[key]


def antiderivative_weights(x1: np.ndarray, n: int) -> np.ndarray:
    """``(N, n)``: ``∫_{-1}^{x1} ℓ_j`` for the Lagrange basis ``ℓ_j`` of :func:`chebyshev`
    points, by the exact antiderivatives of the Chebyshev polynomials,
    ``∫ T_m = (T_{m+1}/(m+1) - T_{m-1}/(m-1)) / 2``."""
    return chebyshev_antiderivatives(x1, n) @ chebyshev(n)[2].T


def chebyshev_antiderivatives(x1: np.ndarray, n: int) -> np.ndarray:
    """``(N, n)``: ``∫_{-1}^{x1} T_m`` for ``m < n`` (:func:`antiderivative_weights` before
    the change to the Lagrange basis, which callers summing over many ``x1`` apply once to
    the sum).

    >>> chebyshev_antiderivatives(np.array([1.0, 0.0]), 3).round(12).tolist()  # ∫ 1, ∫ x, ∫ 2x² - 1
    [[2.0, 0.0, -0.666666666667], [1.0, -0.5, -0.333333333333]]
    """
    m = np.arange(n + 1)
    T = _chebyshev_rows(np.clip(x1, -1.0, 1.0), n + 1)  # (n + 1, N): T_0 .. T_n, rows contiguous
    ends = np.where(m % 2 == 0, 1.0, -1.0)  # T_m(-1)
    I = np.empty((n, len(x1)))
    I[0] = T[1] + 1.0
    if n > 1:
        I[1] = (T[2] - 1.0) / 4.0  # ∫ T_1 = x² / 2 = (T_2 + 1) / 4
    if n > 2:
        k = np.arange(2, n)[:, None]
        I[2:] = (T[3:] / (k + 1) - T[1:-2] / (k - 1)) / 2 - (ends[3:, None] / (k + 1) - ends[1:-2, None] / (k - 1)) / 2
    return I.T


def chebyshev_polynomials(y: np.ndarray, count: int) -> np.ndarray:
    """``(N, count)``: ``T_0(y) .. T_{count-1}(y)`` by the three-term recurrence
    ``T_{m+1} = 2 y T_m - T_{m-1}`` (stable on ``[-1, 1]``; one vector operation per
    degree instead of a cosine per entry).

    >>> y = np.array([-1.0, 0.3, 1.0])
    >>> bool(np.allclose(chebyshev_polynomials(y, 6), np.cos(np.outer(np.arccos(y), np.arange(6))), atol=1e-15))
    True
    """
    return _chebyshev_rows(y, count).T


def _chebyshev_rows(y: np.ndarray, count: int) -> np.ndarray:
    """:func:`chebyshev_polynomials` as ``(count, N)``, each degree's row contiguous."""
    T = np.empty((count, len(y)))  # rows contiguous for the recurrence
    T[0] = 1.0
    if count > 1:
        T[1] = y
    y2 = 2.0 * y
    for m in range(2, count):
        np.multiply(y2, T[m - 1], out=T[m])
        T[m] -= T[m - 2]
    return T


def interpolation_points(degree, order: int) -> tuple[int, bool]:
    """Interpolation points per span along a direction for Green's grid
    (:func:`grids_nodes`): ``5p + 1`` where the surface is a polynomial of degree ``p``
    (the integrands' degree: exact), else ``2 order`` (the polynomial degree Gauss of
    ``order`` integrates exactly).

    >>> interpolation_points(1, 12), interpolation_points(None, 12)
    ((6, True), (24, False))
    """
    if degree is not None and exact_order(degree) <= order:
        return 5 * degree + 1, True
    return 2 * order, False


def green_layout(mf, k: int, P: np.ndarray):
    """Per boundary node: the inner spans wholly below it (``full``), whether the next one
    is partial, and its outer span ``q``."""
    br, obr = mf.breaks[k], mf.breaks[1 - k]
    n_spans = len(br) - 1
    u = P[:, k]
    full = np.searchsorted(br[1:], u, side="right")  # br[i + 1] <= u
    partial = (full < n_spans) & (br[np.minimum(full, n_spans - 1)] < u)
    q = np.clip(np.searchsorted(obr, P[:, 1 - k], side="right") - 1, 0, len(obr) - 2)
    return full, partial, q


def inner_nodes(mf, k: int, m_in: int, P: np.ndarray, wb: np.ndarray, full, partial):
    """Nodes ``(s, other, weights)`` of Green's inner integrals ``∫_{lo}^{P_k} g`` along
    direction ``k`` node by node: Gauss of ``m_in`` on the partial span (its start to
    ``P_k``) and on every whole span below it."""
    x, w = gauss(m_in)
    br = mf.breaks[k]
    u, other = P[:, k], P[:, 1 - k]
    rows = np.flatnonzero(partial)
    reps = full
    node = np.concatenate([rows, np.repeat(np.arange(len(P)), reps)])
    start = np.concatenate([full[rows], np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps)])
    a = br[start]
    b = np.concatenate([u[rows], br[start[len(rows):] + 1]])
    s = ((a + b)[:, None] / 2 + (b - a)[:, None] / 2 * x).ravel()
    ws = ((b - a)[:, None] / 2 * w * wb[node, None]).ravel()
    return s, np.repeat(other[node], m_in), ws


def _sum_rows(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """``(n, ...)``: the rows of ``values`` summed by ``index`` (a sort and one
    ``add.reduceat``: ``np.add.at`` is many times slower)."""
    out = np.zeros((n,) + values.shape[1:])
    if len(index):
        order = np.argsort(index, kind="stable")
        idx = index[order]
        starts = np.flatnonzero(np.concatenate([[True], idx[1:] != idx[:-1]]))
        out[idx[starts]] = np.add.reduceat(values[order], starts, axis=0)
    return out


class GridJob:
    """One face's share of :func:`grids_nodes`: its inner and outer breaks, and per
    boundary node on its grids the inner and outer coordinates, the weight and
    :func:`green_layout`'s ``full``, ``partial`` and ``q``."""

    def __init__(self, inner_breaks, outer_breaks, inner, outer, wb, full, partial, q):
        self.br, self.obr = inner_breaks, outer_breaks
        self.inner, self.outer, self.wb, self.full, self.partial, self.q = inner, outer, wb, full, partial, q


def _padded_breaks(jobs: list, attr: str) -> np.ndarray:
    """``(F, most + 1)``: the faces' breaks, each continued by its last value (spans of
    zero length, which receive no weight)."""
    rows = [getattr(job, attr) for job in jobs]
    out = np.empty((len(rows), max(len(r) for r in rows)))
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
        out[i, len(r):] = r[-1]
    return out


def grids_nodes(jobs: list, counts) -> list:
    """Green's inner integrals of all boundary nodes on one fixed grid per cell (inner span
    × outer span), for many faces (:class:`GridJob` each) with the same ``counts``: on each
    cell the integrands are replaced by their tensor interpolant at ``counts`` Chebyshev
    points (exact where the surface is a polynomial there, see
    :func:`interpolation_points`), whose inner antiderivative is integrated exactly.  Then

        Σ_n wb_n ∫_{lo}^{u_n} g(s, t_n) ds = Σ_cells Σ_jl Ω_jl g(s_j, t_l),

    ``Ω`` summing, over the boundary nodes, ``wb · L_l(t_n) · ∫ ℓ_j`` (over the whole
    spans below the node and the partial one): the surface is evaluated on the grids only,
    whatever the number of boundary nodes.  Returns per face the used cells' points and
    weights (:class:`GreenGrid`).  The faces' cells are laid out on one array padded to
    the most spans of any face (padding spans have zero length and get no weight), so
    every face's sums are the ones it gets alone, term for term, without the fixed cost of
    a pass per face."""
    ks, kt = counts
    xs = chebyshev(ks)[0]
    xt = chebyshev(kt)[0]
    iws = _GAUSS[("span integral", ks)]  # ∫_{-1}^{1} ℓ_j
    n_faces = len(jobs)
    br, obr = _padded_breaks(jobs, "br"), _padded_breaks(jobs, "obr")
    n_spans, n_out = br.shape[1] - 1, obr.shape[1] - 1
    sizes = [len(job.wb) for job in jobs]
    face = np.repeat(np.arange(n_faces), sizes)
    inner, outer, wb, full, partial, q = (np.concatenate([getattr(job, name) for job in jobs]) if n_faces > 1
                                          else getattr(jobs[0], name)
                                          for name in ("inner", "outer", "wb", "full", "partial", "q"))
    row = face * n_out + q  # (face, outer span)
    a, b = obr[face, q], obr[face, q + 1]
    # the outer Lagrange basis ℓ_l = Σ_m At[l, m] T_m is linear: sums over nodes are taken
    # in the Chebyshev basis (N x kt) and changed to the Lagrange basis once per cell.
    # Boundary nodes reach a hair beyond their cell (GRID_REACH): the polynomial continues
    At, As = chebyshev(kt)[2], chebyshev(ks)[2]
    tw = chebyshev_polynomials((2 * outer - a - b) / (b - a), kt) * wb[:, None]  # (N, kt)
    # whole spans: node n covers spans i < full_n; ∫ over a span of ℓ_j is h/2 · iws_j
    # (nodes in their first inner span cover none: left out, as they would only add to a
    # sum nothing reads)
    covers = np.flatnonzero(full > 0)
    acc = _sum_rows((row * (n_spans + 1) + full)[covers], tw[covers], n_faces * n_out * (n_spans + 1)) @ At.T
    acc = acc.reshape(n_faces * n_out, n_spans + 1, kt)
    whole = np.cumsum(acc[:, ::-1], axis=1)[:, ::-1][:, 1:]  # (F Q, S, kt): Σ over nodes with full > i
    h = np.diff(br, axis=1)  # (F, S)
    h_rows = np.repeat(h, n_out, axis=0)  # per (face, outer span)
    omega = (h_rows / 2)[:, :, None, None] * iws[None, None, :, None] * whole[:, :, None, :]
    rows = np.flatnonzero(partial)
    if rows.size:
        # partial span f: ∫_{br_f}^{u_n} ℓ_j, exactly
        f, fr = full[rows], face[rows]
        x1 = (2 * inner[rows] - br[fr, f] - br[fr, f + 1]) / h[fr, f]  # in (-1, 1)
        c = chebyshev_antiderivatives(x1, ks) * (h[fr, f] / 2)[:, None]  # (n, ks), Chebyshev basis
        cell = row[rows] * n_spans + f
        order = np.argsort(cell, kind="stable")
        cell, c, lp = cell[order], c[order], tw[rows[order]]
        cuts = np.flatnonzero(np.diff(cell)) + 1
        starts = np.concatenate([[0], cuts])
        M = np.stack([c[lo:hi].T @ lp[lo:hi] for lo, hi in zip(starts, np.concatenate([cuts, [len(cell)]]))])
        flat = omega.reshape(n_faces * n_out * n_spans, ks, kt)
        flat[cell[starts]] += As @ M @ At.T  # Σ_n c_nj lt_nl per cell, in the Lagrange bases
    used_row, used_si = np.nonzero(np.any(omega != 0.0, axis=(2, 3)))
    bounds = np.searchsorted(used_row, np.arange(n_faces + 1) * n_out)
    out = []
    for i, job in enumerate(jobs):  # each face's used cells, in (outer span, inner span) order
        lo, hi = bounds[i], bounds[i + 1]
        rw, si = used_row[lo:hi], used_si[lo:hi]
        qi = rw - i * n_out
        fb, fo, fh = job.br, job.obr, h[i]
        s = ((fb[si] + fb[si + 1])[:, None] / 2 + (fh[si] / 2)[:, None] * xs)  # (C, ks)
        t = ((fo[qi] + fo[qi + 1])[:, None] / 2 + ((fo[qi + 1] - fo[qi]) / 2)[:, None] * xt)  # (C, kt)
        out.append(GreenGrid(si, qi, s, t, omega[rw, si].ravel()))
    return out


def _used(index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(index, return_inverse=True)`` of small non-negative span indices, by a
    mark per span (no sort)."""
    mark = np.zeros(int(index.max()) + 1 if len(index) else 0, bool)
    mark[index] = True
    return np.flatnonzero(mark), (np.cumsum(mark) - 1)[index]


class GreenGrid:
    """The grid points of :func:`grids_nodes`: per used cell ``c`` (inner span ``si[c]``,
    outer span ``qi[c]``) the tensor ``s[c] × t[c]`` (``(C, ks)``, ``(C, kt)``: inner and
    outer coordinates), flattened cell by cell, inner index before outer, with
    ``weights``; :meth:`coordinates` lays the points out flat, :meth:`derivatives`
    evaluates them through a surface's tensor evaluator (the trigonometry of an
    elementary surface runs on the grid lines, not on every point)."""

    #: evaluate on the full tensor of used inner × outer spans when it holds at most
    #: this many times the points of the used cells (else point by point)
    TENSOR_SLACK = 1.25

    def __init__(self, si, qi, s, t, weights):
        self.si, self.qi, self.s, self.t, self.weights = si, qi, s, t, weights

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat ``(s, t)`` of every grid point."""
        shape = (len(self.qi), self.s.shape[1], self.t.shape[1])
        return np.broadcast_to(self.s[:, :, None], shape).ravel(), np.broadcast_to(self.t[:, None, :], shape).ravel()

    def derivatives(self, k: int, evaluate, grid_evaluate) -> np.ndarray:
        """``(N, 2, 2, 3)`` partials at the grid points (``k``: the inner direction, 0 for
        ``u``): from ``grid_evaluate(us, vs, 1)`` on the used spans' lines when that
        tensor is not much larger than the cells, else ``evaluate(u, v, 1)`` point by point."""
        ks, kt = self.s.shape[1], self.t.shape[1]
        su, s_pos = _used(self.si)
        qu, q_pos = _used(self.qi)
        if grid_evaluate is None or len(su) * len(qu) > self.TENSOR_SLACK * len(self.qi):
            s, t = self.coordinates()
            return evaluate(s, t, 1) if k == 0 else evaluate(t, s, 1)
        # the lines of each used span, once (cells of one span share them)
        s_lines = np.empty((len(su), ks))
        s_lines[s_pos] = self.s
        t_lines = np.empty((len(qu), kt))
        t_lines[q_pos] = self.t
        rows = (s_pos[:, None] * ks + np.arange(ks))[:, :, None]  # (C, ks, 1)
        cols = (q_pos[:, None] * kt + np.arange(kt))[:, None, :]  # (C, 1, kt)
        if k == 0:
            ders = grid_evaluate(s_lines.ravel(), t_lines.ravel(), 1)[rows, cols]
        else:
            ders = grid_evaluate(t_lines.ravel(), s_lines.ravel(), 1)[cols, rows]
        return ders.reshape(-1, *ders.shape[3:])
