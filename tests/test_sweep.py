"""Swept surfaces: the four kinds of the lecture against OCCT's pipe shell (geometric)
and against closed forms (helix frames, sections at the ends, normal planes)."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.construct.sweep import sweep

PATH = sm.BSplineCurve([(0, 0, 0), (0, 0, 4), (3, 1, 8), (8, 0, 9), (10, 3, 12)], 3)
# an asymmetric open profile in the plane z = 0, normal to the path at its start
PROFILE = sm.BSplineCurve([(-1, -1, 0), (0, -1.5, 0), (1, -1, 0), (1.5, 0, 0), (1, 1, 0)], 3)
GUIDE = sm.BSplineCurve([(0, 2, 0), (0, 2.5, 4), (3, 3, 8), (8, 1, 9), (10, 4, 12)], 3)


def _helix():
    import build123d as bd

    helix = bd.Edge.make_helix(pitch=4, height=8, radius=3)
    p0 = tuple(helix.position_at(0))
    t0 = tuple(helix.tangent_at(0))
    return helix, bd.Edge.make_ellipse(1.0, 0.3, bd.Plane(origin=p0, z_dir=t0))


def _end_section(mode, scale=0.5):
    s0 = sweep(PROFILE, PATH, mode=mode)
    r = s0.frames(np.array([0.0, 1.0]))
    p = PATH.points(np.array([0.0, 1.0]))
    m = np.eye(4)
    m[:3, :3] = scale * r[1] @ r[0].T
    m[:3, 3] = p[1] - m[:3, :3] @ p[0]
    return PROFILE.transformed(m)


@pytest.mark.parametrize("mode", ["frenet", "corrected_frenet"])
@pytest.mark.parametrize("kind", ["plain", "twist", "end_profile", "guide"])
def test_matches_occt_pipe_shell(mode, kind):
    kw = {"plain": {}, "twist": {"twist": 120.0}, "end_profile": {"end_profile": _end_section(mode)},
          "guide": {"guide": GUIDE}}[kind]
    s = sweep(PROFILE, PATH, mode=mode, **kw)
    assert not s.exact_in_occt
    r = sm.crosscheck(s, samples=12)
    assert r.mode == "geometric"
    # OCCT approximates the pipe to ~1e-6; 1e-6 relative to the ~15-unit size
    assert r.max_deviation < 1.5e-5, r
    assert r.passed


def test_helix_frames_closed_form():
    helix, ellipse = _helix()
    fr = sweep(ellipse, helix, mode="frenet")
    rmf = sweep(ellipse, helix, mode="corrected_frenet")
    (v0, v1) = fr.domain[1]
    v = np.linspace(v0, v1, 9)
    p = fr.path.points(v)
    rf, rr = fr.frames(v), rmf.frames(v)
    # Frenet normal of a helix points at its axis
    radial = -p[:, :2] / np.linalg.norm(p[:, :2], axis=1)[:, None]
    assert np.abs(rf[:, :2, 1] - radial).max() < 1e-5 and np.abs(rf[:, 2, 1]).max() < 1e-5
    # rotation-minimizing frame = Frenet turned by -tau * s, tau = c / (r^2 + c^2)
    c, radius = 4 / (2 * np.pi), 3.0
    tau = c / (radius**2 + c**2)
    s = v / v1 * 2 * np.hypot(2 * np.pi * radius, 4)  # arc length (2 turns)
    s = np.array([fr.path.segment(v0, x).length() if x > v0 else 0.0 for x in v])
    ang = np.arctan2(np.einsum("ij,ij->i", np.cross(rf[:, :, 1], rr[:, :, 1]), rf[:, :, 0]),
                     np.einsum("ij,ij->i", rf[:, :, 1], rr[:, :, 1]))
    assert np.abs(np.unwrap(ang) + tau * s).max() < 1e-4
    assert sm.crosscheck(fr, samples=10).passed


def test_occt_native_corrected_frenet_is_only_approximately_rotation_minimizing():
    s = sweep(PROFILE, PATH, mode="corrected_frenet")
    from surfmod.occ.sample import distances_to_face

    pts = s.grid(np.linspace(0, 1, 10), np.linspace(0, 1, 10)).reshape(-1, 3)
    native = distances_to_face(s.occt_native().wrapped, pts).max()
    assert 1e-3 < native < 0.3  # OCCT's angle law is coarse (measured ~0.12 here)


def test_closed_forms_of_the_sections():
    # rigid frames keep a profile drawn in the normal plane in the normal planes
    s = sweep(PROFILE, PATH, mode="corrected_frenet", twist=45.0)
    u = np.linspace(0, 1, 7)[:, None]
    v = np.linspace(0, 1, 9)[None, :]
    pts = s.points(u, v)
    d = PATH.derivatives(v[0], 1)
    t = d[:, 1] / np.linalg.norm(d[:, 1], axis=1)[:, None]
    assert np.abs(np.einsum("ijk,jk->ij", pts - d[None, :, 0], t)).max() < 1e-12
    # distances to the path are preserved
    r0 = np.linalg.norm(PROFILE.points(u[:, 0]) - PATH.points(0.0), axis=1)
    assert np.abs(np.linalg.norm(pts - d[None, :, 0], axis=-1) - r0[:, None]).max() < 1e-12
    # twist: the end frame is the untwisted one turned by 45 degrees about the tangent
    plain = sweep(PROFILE, PATH, mode="corrected_frenet")
    a, b = plain.frames(1.0), s.frames(1.0)
    assert np.isclose(a[:, 1] @ b[:, 1], np.cos(np.radians(45)), atol=1e-12)
    # changing profile: exact start and end sections, halfway blend in the frame
    end = _end_section("frenet", 0.5)
    ch = sweep(PROFILE, PATH, mode="frenet", end_profile=end)
    uu = np.linspace(0, 1, 11)
    assert np.abs(ch.points(uu, 0.0) - PROFILE.points(uu)).max() < 1e-12
    assert np.abs(ch.points(uu, 1.0) - end.points(uu)).max() < 1e-12
    mid = ch.points(uu, 0.5) - PATH.points(0.5)
    full = sweep(PROFILE, PATH, mode="frenet").points(uu, 0.5) - PATH.points(0.5)
    assert np.abs(mid - 0.75 * full).max() < 1e-12


def test_guide_sets_the_normal_and_derivatives():
    s = sweep(PROFILE, PATH, guide=GUIDE)
    v = np.linspace(0, 1, 7)
    r = s.frames(v)
    p = PATH.points(v)
    # the normal points at the guide: the guide crosses the ray P + t N (t > 0)
    q = GUIDE.points(np.linspace(0, 1, 4001))
    for k in range(7):
        rel = q - p[k]
        dist_plane = rel @ r[k][:, 0]
        j = np.argmin(np.abs(dist_plane))
        off = rel[j] - dist_plane[j] * r[k][:, 0]
        assert np.allclose(off / np.linalg.norm(off), r[k][:, 1], atol=2e-3)
    # v-derivatives (finite differences) agree with differences of points
    d = s.derivatives(0.4, 0.37, order=2)
    h = 1e-4
    fd = (s.points(0.4, 0.37 + h) - s.points(0.4, 0.37 - h)) / (2 * h)
    assert np.allclose(d[0, 1], fd, atol=1e-6)
    fdu = (s.points(0.4 + h, 0.37) - s.points(0.4 - h, 0.37)) / (2 * h)
    assert np.allclose(d[1, 0], fdu, atol=1e-6)


def test_bad_inputs():
    cusp = sm.BezierCurve([(0, 0, 0), (2, 2, 0), (0, 2, 0), (2, 0, 0)])  # zero tangent at t = 1/2
    with pytest.raises(sm.SurfmodError, match="path: has a cusp"):
        sweep(PROFILE, cusp)
    with pytest.raises(sm.SurfmodError, match="mode"):
        sweep(PROFILE, PATH, mode="fixed")
    with pytest.raises(sm.SurfmodError, match="twist"):
        sweep(PROFILE, PATH, twist=float("nan"))
    with pytest.raises(sm.SurfmodError, match="profile"):
        sweep("circle", PATH)
    inflect = sm.BSplineCurve([(0, 0, 0), (3, 2, 0), (6, -2, 0), (9, 0, 0)], 3)
    with pytest.raises(sm.SurfmodError, match="path: the curvature vanishes"):
        sweep(PROFILE, inflect, mode="frenet")
    # the corrected (rotation-minimizing) frame handles the inflection
    assert sweep(PROFILE, inflect, mode="corrected_frenet").points(0.5, 0.5).shape == (3,)
    # a copy of the profile merely translated to the path end is turned round in the
    # end frame here: refused (OCCT would silently flip it)
    with pytest.raises(sm.SurfmodError, match="end_profile: runs opposite to profile"):
        sweep(PROFILE, PATH, end_profile=PROFILE.translated(PATH.points(1.0)))
    with pytest.raises(sm.SurfmodError, match="order"):
        sweep(PROFILE, PATH).derivatives(0.5, 0.5, order=3)


def test_coiled_path_and_short_guide():
    helix, ellipse = _helix()
    s = sweep(ellipse, helix, mode="corrected_frenet", twist=30.0)
    r = sm.crosscheck(s, samples=10)
    assert r.passed and r.max_deviation < 1e-5
    short = GUIDE.segment(0.0, 0.6)
    with pytest.raises(sm.SurfmodError, match="guide: does not cross the normal plane"):
        sweep(PROFILE, PATH, guide=short)


def test_similarity_transform_moves_the_sweep():
    s = sweep(PROFILE, PATH, mode="corrected_frenet", twist=60.0)
    moved = s.rotated((1, 2, 3), (0.3, -1, 0.5), 40.0).scaled(2.0)
    u = np.linspace(0, 1, 5)[:, None]
    v = np.linspace(0, 1, 6)[None, :]
    from surfmod.transforms import rotation_matrix, scale_matrix

    m = scale_matrix(2.0) @ rotation_matrix((1, 2, 3), (0.3, -1, 0.5), 40.0)
    expect = s.points(u, v) @ m[:3, :3].T + m[:3, 3]
    assert np.abs(moved.points(u, v) - expect).max() < 1e-9
    with pytest.raises(sm.SurfmodError, match="matrix: a swept surface"):
        s.scaled((1.0, 2.0, 1.0))
    # a mirror reverses the handedness of the frames: the twist law is mirrored too
    from surfmod.transforms import mirror_matrix

    for kw in ({"mode": "frenet", "twist": 60.0}, {"guide": GUIDE, "guide_scale": True, "twist": 30.0}):
        t = sweep(PROFILE, PATH, **kw)
        mm = mirror_matrix((1, 0, 2), (0.3, 1, -0.2))
        mirrored = t.mirrored((1, 0, 2), (0.3, 1, -0.2))
        assert np.abs(mirrored.points(u, v) - (t.points(u, v) @ mm[:3, :3].T + mm[:3, 3])).max() < 1e-9


def test_rotation_minimizing_table_has_no_spin():
    # along the RMF the normal's derivative has no binormal component: r' . b = 0
    s = sweep(PROFILE, PATH, mode="corrected_frenet")
    v = np.linspace(0.05, 0.95, 19)
    h = 1e-5
    r0, r1 = s.frames(v - h), s.frames(v + h)
    dr = (r1[:, :, 1] - r0[:, :, 1]) / (2 * h)
    b = s.frames(v)[:, :, 2]
    assert np.abs(np.sum(dr * b, axis=1)).max() < 1e-6


def test_straight_path_gives_a_cylinder_like_sweep():
    # on a straight path the Frenet frame is undefined; the frame stays fixed instead
    s = sweep(PROFILE, sm.Line((0, 0, 0), (0, 0, 10)), mode="frenet")
    u = np.linspace(0, 1, 7)
    for z in (0.0, 4.0, 10.0):
        assert np.abs(s.points(u, z) - (PROFILE.points(u) + (0, 0, z))).max() < 1e-12
    assert sm.crosscheck(s, samples=8).max_deviation < 1e-6


def test_guide_rail_scaling():
    s = sweep(PROFILE, PATH, guide=GUIDE, guide_scale=True)
    r = sm.crosscheck(s, samples=12)
    assert r.passed and r.max_deviation < 1.5e-5
    # the section grows with the rail's distance from the path (in the normal plane)
    v = np.linspace(0, 1, 9)
    u = np.linspace(0, 1, 5)
    d = PATH.derivatives(v, 1)
    t = d[:, 1] / np.linalg.norm(d[:, 1], axis=1)[:, None]
    q = GUIDE.points(np.linspace(0, 1, 20001))
    dist = []
    for k in range(9):
        rel = q - d[k, 0]
        j = np.argmin(np.abs(rel @ t[k]))
        dist.append(np.linalg.norm(rel[j] - (rel[j] @ t[k]) * t[k]))
    ratio = np.array(dist) / dist[0]
    r0 = np.linalg.norm(PROFILE.points(u) - PATH.points(0.0), axis=1)
    got = np.linalg.norm(s.points(u[:, None], v[None, :]) - d[None, :, 0], axis=-1)
    assert np.abs(got - r0[:, None] * ratio[None, :]).max() < 2e-3  # sampled rail: ~1e-4
    with pytest.raises(sm.SurfmodError, match="guide_scale: scaling to a guide rail needs guide="):
        sweep(PROFILE, PATH, guide_scale=True)
    with pytest.raises(sm.SurfmodError, match="guide_scale: .* cannot be combined with end_profile"):
        sweep(PROFILE, PATH, guide=GUIDE, guide_scale=True, end_profile=_end_section("frenet"))
