"""Welding a triangle soup's vertices (surfmod.meshing.polymesh.weld): the result is
NumPy's ``np.unique(axis=0)`` of the vertices (lexicographic order) with the triangles
renumbered, and triangles that collapse onto an edge or a point are dropped."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from surfmod.meshing.polymesh import weld


@given(st.integers(0, 2**32 - 1), st.integers(1, 400))
def test_weld_equals_unique_rows_and_drops_collapsed_triangles(seed, n):
    rng = np.random.default_rng(seed)
    vertices = np.round(rng.standard_normal((n, 3)) * 2) / 2  # coarse values: many repeats
    vertices[rng.random(n) < 0.1] *= -0.0  # signed zeros weld with zeros
    triangles = rng.integers(0, n, (max(1, n // 2), 3))
    unique, tri, kept = weld(vertices, triangles)
    expected, inverse = np.unique(vertices, axis=0, return_inverse=True)
    renumbered = inverse.reshape(-1)[triangles]
    keep = (renumbered[:, 0] != renumbered[:, 1]) & (renumbered[:, 1] != renumbered[:, 2]) & (
        renumbered[:, 0] != renumbered[:, 2])
    assert np.array_equal(unique, expected)
    assert np.array_equal(tri, renumbered[keep]) and np.array_equal(kept, keep)
    assert np.array_equal(unique[tri], vertices[triangles[keep]])


def test_weld_of_nothing():
    unique, tri, _ = weld(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    assert unique.shape == (0, 3) and tri.shape == (0, 3)
