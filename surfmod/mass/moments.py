"""Stage six of the mass pipeline (:mod:`surfmod.mass`): the divergence-theorem integrands
``[area, V, M(3), S(3, 3)]`` summed over quadrature nodes, face by face or for many faces
in one pass.

>>> import numpy as np
>>> ders = np.zeros((1, 2, 2, 3)); ders[0, 1, 0], ders[0, 0, 1] = (1, 0, 0), (0, 1, 0)
>>> float(node_moments(ders, np.array([2.0]), np.zeros(3))[0])  # area: weight times |Su x Sv|
2.0
"""

from __future__ import annotations

import numpy as np

from .nodes import face_nodes, mass_face


def node_moments(ders: np.ndarray, weights: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """[area, V, M(3), S(3,3)] contributions from partials at quadrature nodes (``Su``
    already signed so that ``Su × Sv`` is the outward ``n dA``)."""
    return _moments_of_groups(ders, weights, ref, [0, len(weights)])[0]


def _moments_of_groups(ders: np.ndarray, weights: np.ndarray, ref: np.ndarray, bounds) -> np.ndarray:
    """``(G, 14)``: :func:`node_moments` of the node groups ``[bounds[g], bounds[g + 1])``,
    the integrands computed once for all of them and summed group by group (each sum the
    one the group's own call makes, bit for bit: contiguous rows, pairwise)."""
    # (3, N) rows, contiguous: np.sum then reduces each row pairwise, which keeps the 1e-14
    # of the closed forms (a reduction over axis 0 of (N, 3), or a BLAS dot, does not)
    x = np.ascontiguousarray((ders[:, 0, 0] - ref).T)
    su, sv = ders[:, 1, 0].T, ders[:, 0, 1].T
    n = np.empty_like(x)  # Su x Sv, written out
    n[0] = su[1] * sv[2] - su[2] * sv[1]
    n[1] = su[2] * sv[0] - su[0] * sv[2]
    n[2] = su[0] * sv[1] - su[1] * sv[0]
    area = weights * np.sqrt(np.sum(n * n, axis=0))
    vol = weights * np.sum(x * n, axis=0)  # w x·n: the radial fields below all carry it
    first = vol * x  # w x_i (x·n), (3, N)
    second = first[:, None, :] * x[None, :, :]  # w x_i x_j (x·n), (3, 3, N)
    out = np.empty((len(bounds) - 1, 14))
    for g, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:])):
        out[g, 0] = float(np.sum(area[lo:hi]))
        out[g, 1] = float(np.sum(vol[lo:hi])) / 3.0
        out[g, 2:5] = np.sum(first[:, lo:hi], axis=1) / 4.0
        out[g, 5:] = np.sum(second[:, :, lo:hi], axis=2).ravel() / 5.0
    return out


class MomentAccumulator:
    """Sums :func:`node_moments` over many faces in ``groups`` separate totals (e.g. rules
    exact by degree and the others), evaluating them in batches of about ``BATCH`` nodes
    (one NumPy pass for many small faces and both groups, bounded memory for big ones)."""

    BATCH = 200_000

    def __init__(self, ref: np.ndarray, groups: int = 1):
        self.ref, self.totals, self.size = ref, np.zeros((groups, 14)), 0
        self.parts = [[] for _ in range(groups)]

    def add(self, ders: np.ndarray, weights: np.ndarray, group: int = 0) -> None:
        self.parts[group].append((ders, weights))
        self.size += len(weights)
        if self.size >= self.BATCH:
            self.flush()

    def flush(self) -> np.ndarray:
        """The totals, ``(groups, 14)`` (one group: its row)."""
        pieces = [piece for parts in self.parts for piece in parts]
        if pieces:
            counts = [sum(len(w) for _, w in parts) for parts in self.parts]
            ders = np.concatenate([d for d, _ in pieces]) if len(pieces) > 1 else pieces[0][0]
            weights = np.concatenate([w for _, w in pieces]) if len(pieces) > 1 else pieces[0][1]
            bounds = np.concatenate([[0], np.cumsum(counts)])
            live = [g for g, c in enumerate(counts) if c]  # an empty group adds nothing
            sums = _moments_of_groups(ders, weights, self.ref, bounds)
            self.totals[live] += sums[live]
            self.parts, self.size = [[] for _ in self.parts], 0
        return self.totals[0] if len(self.totals) == 1 else self.totals


def face_moments(face, ref=(0.0, 0.0, 0.0), order: int = 12) -> np.ndarray:
    """``[area, V, M(3), S(3, 3)]`` of one face read back with :func:`surfmod.from_face`
    (its trimmed region; ``V`` etc. are the face's share of the divergence-theorem
    integrals about ``ref``).

    >>> import surfmod as sm, build123d as bd
    >>> round(float(face_moments(sm.from_face(bd.Box(2, 3, 4).faces()[0]))[0]), 12)
    12.0
    """
    ders, w, _ = face_nodes(mass_face(face), order)
    return node_moments(ders, w, np.asarray(ref, dtype=float))
