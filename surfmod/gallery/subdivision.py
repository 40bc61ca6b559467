"""Gallery entries for subdivision surfaces (issue 5): Catmull–Clark limit surfaces of
coarse cages turned into CAD solids (exact bicubic B-spline patches where the mesh is
regular, measured approximate Bézier patches at extraordinary vertices)."""

from __future__ import annotations

import numpy as np

from ..subdiv.limit import limit_surface
from . import entry

CUBE_VERTICES = np.array(
    [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)], dtype=float
) * 10.0
CUBE_FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def prism_cage(sides: int = 5, radius: float = 8.0, height: float = 12.0):
    """A closed prism cage: two ``sides``-gons and ``sides`` quads (mixed polygons)."""
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.stack([radius * np.cos(a), radius * np.sin(a), np.zeros(sides)], 1)
    vertices = np.concatenate([ring, ring + [0.0, 0.0, height]])
    faces = [list(range(sides - 1, -1, -1)), list(range(sides, 2 * sides))]
    faces += [[i, (i + 1) % sides, sides + (i + 1) % sides, sides + i] for i in range(sides)]
    return vertices, faces


def torus_cage(n: int = 8, m: int = 6, major: float = 12.0, minor: float = 4.0):
    """A periodic quad grid around a torus: every vertex regular (valence 4)."""
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = 2 * np.pi * i / n, 2 * np.pi * j / m
    r = major + minor * np.cos(b)
    vertices = np.stack([r * np.cos(a), r * np.sin(a), minor * np.sin(b)], -1).reshape(-1, 3)
    p, q = (x.ravel() for x in np.meshgrid(np.arange(n), np.arange(m), indexing="ij"))
    faces = np.stack([p * m + q, ((p + 1) % n) * m + q, ((p + 1) % n) * m + (q + 1) % m, p * m + (q + 1) % m], 1)
    return vertices, faces


@entry("subdivision_cube", "Catmull–Clark limit of a cube cage (solid)", "sm.limit_surface(v, quads).solid()")
def _cube():
    return limit_surface(CUBE_VERTICES, CUBE_FACES, levels=2).solid()


@entry("subdivision_prism", "Catmull–Clark limit of a pentagonal prism (mixed polygons)", "sm.limit_surface(v, faces, levels=1).solid()")
def _prism():
    return limit_surface(*prism_cage(), levels=1).solid()


@entry("subdivision_torus", "Catmull–Clark limit of a regular torus cage (exact B-splines)", "sm.limit_surface(v, quads, levels=0).solid()")
def _torus():
    return limit_surface(*torus_cage(), levels=0).solid()


@entry("subdivision_creased", "Catmull–Clark limit with a sharp crease loop", "sm.limit_surface(v, quads, creases=ring).solid()")
def _creased():
    ring = [(0, 1), (1, 2), (2, 3), (3, 0)]  # the bottom square stays a sharp edge
    return limit_surface(CUBE_VERTICES, CUBE_FACES, levels=2, creases=ring).solid()
