"""The compiled Gauss-Newton distance bounds (project_distances_compiled, used by
mesh measurement on B-spline faces) equal the NumPy iteration of
surfmod.ops.closest.project_distances to round-off: polynomial and rational
nets, a periodic direction (parameters past the seam wrap), guesses outside the box
(clipped), thresholds that stop the iteration early; and every value is a distance to
a point of the surface (an upper bound of the true distance)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import fresh_python

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing.facesurface import FaceSurface
from surfmod.occ.topo import face_surface
from surfmod.ops.closest import project_distances


def _surfaces():
    net = wavy_net(7, 6)
    weights = 1.0 + 0.6 * np.random.default_rng(5).random((7, 6))
    plain = face_surface(sm.BSplineSurface(net, (3, 2)).face())[0]
    rational = face_surface(sm.BSplineSurface(net, (2, 3), weights=weights).face())[0]
    periodic = rational.Copy()
    periodic.SetUPeriodic()
    return {"plain": plain, "rational": rational, "periodic": periodic}


@pytest.mark.parametrize("name", ["plain", "rational", "periodic"])
@pytest.mark.parametrize("threshold", [0.0, 0.05])
def test_compiled_projection_equals_numpy(name, threshold):
    ev = FaceSurface(_surfaces()[name])
    assert ev.projector is not None
    rng = np.random.default_rng(11)
    (u0, u1), (v0, v1) = ev.range
    uv = np.column_stack([rng.uniform(u0 - 0.2, u1 + 0.2, 400), rng.uniform(v0 - 0.2, v1 + 0.2, 400)])
    if ev.periodic[0]:
        uv[:50, 0] += ev.period[0]  # past the seam: wraps
    # points off the surface, their guesses disturbed
    points = ev.d0(uv[:, 0], uv[:, 1]) + 0.1 * rng.standard_normal((400, 3))
    guesses = uv + 0.05 * rng.standard_normal((400, 2))
    box = (u0 - 0.1, u1 + 0.1, v0, v1) if ev.periodic[0] else (u0, u1, v0, v1)
    ours = ev.projector(points, guesses, box, threshold)
    numpy_path = project_distances(ev.d1, points, guesses, box, threshold=threshold, d0=ev.d0)
    scale = float(np.abs(points).max())
    assert np.max(np.abs(ours - numpy_path)) <= 1e-12 * scale
    assert np.all(ours >= 0)


def test_projection_finds_the_foot_point_of_points_off_the_surface():
    ev = FaceSurface(_surfaces()["rational"])
    (u0, u1), (v0, v1) = ev.range
    u = np.linspace(u0 + 0.1, u1 - 0.1, 9)
    v = np.linspace(v0 + 0.1, v1 - 0.1, 9)
    uu, vv = (g.ravel() for g in np.meshgrid(u, v, indexing="ij"))
    d = ev.d1(uu, vv)
    normal = np.cross(d[:, 1, 0], d[:, 0, 1])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    offset = 1e-3  # small enough that every foot point is the base point
    points = d[:, 0, 0] + offset * normal
    got = ev.projector(points, np.column_stack([uu, vv]) + 0.01, (u0, u1, v0, v1))
    # an upper bound (a point of the surface), within the stopping rule's 1e-6 relative
    assert np.all(got >= offset * (1 - 1e-12))
    assert np.allclose(got, offset, rtol=1e-6, atol=0)


def test_packed_segments_equal_one_call_per_net():
    """surfmod.eval.packed runs many nets' projections in one call, segment by segment,
    each with its own start and threshold: the values of one projector call per net."""
    from surfmod.eval.packed import pack, project_segments

    evs = [FaceSurface(s) for s in _surfaces().values()]
    rng = np.random.default_rng(7)
    pts, guesses, boxes, expected, segments, start, stop = [], [], [], [], [], [], []
    at = 0
    for f, ev in enumerate(evs):
        (u0, u1), (v0, v1) = ev.range
        box = (u0, u1, v0, v1)
        for first, last in ((0.05, 0.05), (0.05, 0.0), (0.0, 0.0)):
            uv = np.column_stack([rng.uniform(u0, u1, 150), rng.uniform(v0, v1, 150)])
            p = ev.d0(uv[:, 0], uv[:, 1]) + 0.08 * rng.standard_normal((150, 3))
            g = uv + 0.03 * rng.standard_normal((150, 2))
            # start above threshold: the one-net kernel called as the packed one calls it
            from surfmod.eval import projection_kernel as pkern
            net = ev._spline._local_net()
            ref = np.empty(150)
            pkern.project_distances_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, net.rational,
                                             net.inv_u, net.inv_v, net.bucket_u, net.bucket_v, *ev.parameter_map,
                                             np.array(box), p, g, last, ref, first)
            if first == last:
                np.testing.assert_array_equal(ref, ev.projector(p, g, box, last))
            pts.append(p), guesses.append(g), expected.append(ref)
            segments.append((f, at, at + 150)), start.append(first), stop.append(last)
            at += 150
        boxes.append(box)
    pk = pack([ev._spline._local_net() for ev in evs], *(np.array([ev.parameter_map[k] for ev in evs])
                                                        for k in range(4)))
    got = project_segments(pk, np.array(boxes), np.concatenate(pts), np.concatenate(guesses), np.array(segments),
                           np.array(start), np.array(stop))
    np.testing.assert_array_equal(got, np.concatenate(expected))


def test_the_meshers_projections_compile_one_signature(tmp_path):
    """The B-rep mesher's deviation judge calls the Gauss-Newton kernel from the packed
    kernels (triangles, nodes) and per face (``FaceSurface.projector``): every call passes
    the same argument types (``start`` included), so a first mesh of a B-spline part
    compiles it once, not once per caller (each compile took 5-6 s of a cold
    `surfmod mesh`).  Counted in a fresh process with an empty numba cache (a kernel whose
    caller is loaded from the cache is not compiled, and has no signature)."""
    script = (
        "import numpy as np, surfmod as sm\n"
        "from surfmod.gallery.synthetic import wavy_net\n"
        "from surfmod.eval import packed, projection_kernel\n"
        "from surfmod.meshing.facesurface import FaceSurface\n"
        "from surfmod.occ.topo import face_surface\n"
        "s = sm.BSplineSurface(wavy_net(5, 4), (3, 2))\n"
        "ev = FaceSurface(face_surface(s.face())[0])\n"
        "pk = packed.pack([s._local_net()], *(np.array([ev.parameter_map[k]]) for k in range(4)))\n"
        "box = np.array([[0, 1, 0, 1.0]])\n"
        "uv = np.array([[0.2, 0.2], [0.8, 0.2], [0.5, 0.8]])\n"
        "pts = s.points(uv[:, 0], uv[:, 1]) + 0.01\n"
        "packed.triangle_deviations_compiled(pk, box, pts, uv, np.array([[0, 1, 2]]), np.array([[0, 0, 1]]),\n"
        "                           np.array([[1 / 3] * 3]), np.zeros(1))\n"
        "packed.project_segments(pk, box, pts, uv, np.array([[0, 0, 3]]), np.zeros(1), np.zeros(1))\n"
        "ev.projector(pts, uv, (0, 1, 0, 1), 0.0)\n"
        "print(len(projection_kernel.project_distances_compiled.signatures))\n"
    )
    assert fresh_python(script, env={"NUMBA_CACHE_DIR": str(tmp_path)}) == ["1"]
