"""Facts about a surface's parameter domain that every tessellator needs: which sides
collapse to a point (poles) and which directions close on themselves (seams), so that
their vertices are shared and the mesh is watertight."""

from __future__ import annotations

import numpy as np


def domain_sides(s, size: float):
    """``(degenerate, closed_u, closed_v)``: which domain sides (``"u0"``, ``"u1"``,
    ``"v0"``, ``"v1"``) collapse to a point and which directions close on themselves.

    >>> import surfmod as sm
    >>> deg, cu, cv = domain_sides(sm.sphere(1.0), 2.0)
    >>> sorted(k for k, d in deg.items() if d), cu, cv
    (['v0', 'v1'], True, False)
    """
    (u0, u1), (v0, v1) = s.domain
    t = np.linspace(0.0, 1.0, 33)
    us, vs = u0 + t * (u1 - u0), v0 + t * (v1 - v0)
    eps = 1e-9 * max(size, 1e-300)
    side = {
        "u0": s.points(np.full_like(vs, u0), vs),
        "u1": s.points(np.full_like(vs, u1), vs),
        "v0": s.points(us, np.full_like(us, v0)),
        "v1": s.points(us, np.full_like(us, v1)),
    }
    degenerate = {k: bool(np.ptp(p, axis=0).max() <= eps) for k, p in side.items()}
    closed_u = not degenerate["u0"] and bool(np.abs(side["u0"] - side["u1"]).max() <= eps)
    closed_v = not degenerate["v0"] and bool(np.abs(side["v0"] - side["v1"]).max() <= eps)
    return degenerate, closed_u, closed_v


def shared_points(i: np.ndarray, j: np.ndarray, last_i: int, last_j: int, sides):
    """The grid point that stands for each integer point ``(i, j)`` of ``[0, last_i] x
    [0, last_j]`` (``sides`` from :func:`domain_sides`), so that meshes keyed by it share
    their vertices across seams and poles: a closed direction's last line is its first,
    then every point of a collapsed side is that side's first corner.  Closing comes first:
    where a side is both closed and collapsed, its points already stand on the other
    side, and collapsing them apart from it would open the seam.

    >>> deg = {"u0": False, "u1": False, "v0": False, "v1": True}
    >>> i, j = shared_points(np.array([2, 2]), np.array([0, 3]), 4, 3, (deg, False, True))
    >>> i.tolist(), j.tolist()
    ([2, 2], [0, 0])
    """
    degenerate, closed_u, closed_v = sides
    i, j = i.copy(), j.copy()
    if closed_u:
        i[i == last_i] = 0
    if closed_v:
        j[j == last_j] = 0
    for name, mask, fix in (("u0", i == 0, (0, 0)), ("u1", i == last_i, (last_i, 0)),
                            ("v0", j == 0, (0, 0)), ("v1", j == last_j, (0, last_j))):
        if degenerate[name]:
            i[mask], j[mask] = fix
    return i, j
