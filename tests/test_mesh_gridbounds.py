"""The NumPy lattice bounds (meshing/gridbounds.py) equal the compiled loops
(meshing/gridmesh_kernels.py) bit for bit, on real lattices of surfaces and on hostile ones
(degenerate cells, a pole, NaN), and meshes do not depend on which ran."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing import gridbounds, gridmesh_kernels, gridmesh


def _lattice(s, ncu, ncv, K=gridmesh.K):
    us = np.linspace(*s.domain[0], ncu * K + 1)
    vs = np.linspace(*s.domain[1], ncv * K + 1)
    return np.ascontiguousarray(s.grid(us, vs))


def _compare(S, K, kmax):
    ncu, ncv = (S.shape[0] - 1) // K, (S.shape[1] - 1) // K
    diag = np.zeros((ncu, ncv), bool)
    gridmesh_kernels.diagonals(S, K, diag)
    np.testing.assert_array_equal(gridbounds.diagonals(S, K, (ncu, ncv)), diag)
    est, Q = np.empty(S.shape[:2]), np.empty_like(S)
    gridmesh_kernels.estimates(S, K, diag, kmax, est, Q)
    est2, Q2 = gridbounds.estimates(S, K, diag, kmax)
    np.testing.assert_array_equal(Q2, Q)
    np.testing.assert_array_equal(est2, est)
    parts = [np.full((ncu, ncv), -1.0) for _ in range(3)]
    gridmesh_kernels.cell_maxima(est, K, *parts)
    for mine, theirs in zip(gridbounds.cell_maxima(est, K, (ncu, ncv)), parts):
        np.testing.assert_array_equal(mine, theirs)


@pytest.mark.parametrize("surface", [
    sm.BSplineSurface(wavy_net(8, 8), (3, 3)),
    sm.torus(3.0, 1.0),
    sm.sphere(2.0),  # poles: degenerate tangent planes
])
@pytest.mark.parametrize("K", [2, gridmesh.K])
def test_numpy_bounds_equal_the_compiled_loops(surface, K):
    _compare(_lattice(surface, 7, 5, K), K, 0.8)


def test_numpy_bounds_equal_the_compiled_loops_on_hostile_lattices():
    rng = np.random.default_rng(2)
    K = gridmesh.K
    S = rng.normal(size=(3 * K + 1, 2 * K + 1, 3))
    S[K : 2 * K, :K] = 0.0  # collapsed cells
    S[1, 1] = np.nan
    S[-1, -1] = np.inf
    with np.errstate(invalid="ignore", over="ignore"):
        _compare(S, K, 3.0)


def test_mesh_is_the_same_whichever_path_bounds_it(monkeypatch):
    s = sm.BSplineSurface(wavy_net(8, 8), (3, 3))
    small = sm.tessellate(s, 0.05)
    monkeypatch.setattr(gridmesh, "COMPILED_LATTICE", 0)
    compiled = sm.tessellate(s, 0.05)
    np.testing.assert_array_equal(small.vertices, compiled.vertices)
    np.testing.assert_array_equal(small.faces, compiled.faces)
