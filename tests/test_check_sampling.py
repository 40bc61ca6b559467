"""``surfmod check``'s fast path: sufficient OCCT sampling (``crosscheck(...,
sampling="sufficient")``) and the batched comparison (``crosscheck_many``).  The fast path
must give the dense check's verdict and figures (round-off aside) and still fail on a
wrong evaluator."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from surfmod.occt_crosscheck import crosscheck_many, sufficient_parameters

from conftest import CORPUS


def test_elementary_directions_take_five_values_with_four_distinct_angles():
    c = sm.CylindricalSurface(2.0, v_range=(0, 5))
    u = sufficient_parameters(c, 0, 24)
    np.testing.assert_allclose(u, np.linspace(0, 2 * math.pi, 5), rtol=0, atol=0)
    assert len(np.unique(np.round(np.mod(u, 2 * math.pi), 12))) == 4
    assert sufficient_parameters(c, 1, 3).tolist() == [0.0, 2.5, 5.0]  # never more than asked


def test_spline_directions_take_p_plus_2_per_span_and_every_knot(rng):
    ku = [0, 0, 0, 0.2, 0.5, 1, 1, 1]  # degree 2, three spans
    s = sm.BSplineSurface(rng.uniform(-1, 1, (5, 4, 3)), (2, 3), (ku, [0] * 4 + [1] * 4))
    u = sufficient_parameters(s, 0, 24)
    assert len(u) == 3 * 3 + 1 and {0.2, 0.5} <= set(u.tolist())
    v = sufficient_parameters(s, 1, 24)
    assert v.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    rational = sm.BSplineSurface(s.control_points, (2, 3), (ku, [0] * 4 + [1] * 4), weights=rng.uniform(0.5, 2, (5, 4)))
    assert len(sufficient_parameters(rational, 0, 24)) == 3 * 5 + 1  # 2p + 2 per span
    assert len(sufficient_parameters(rational, 0, 8)) == 8 + 2  # the dense set when smaller


def test_a_periodic_direction_across_its_seam_gets_the_shifted_knots(rng):
    """A face of a u-periodic spline trimmed across the seam, ``u`` in [0.6, 1.4] of a
    period 1: the knots 0.75, 1.0 and 1.25 (0.25 shifted by the period) end spans."""
    from surfmod.readback import TrimmedFace

    ku = [0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1]
    s = sm.BSplineSurface(rng.uniform(-1, 1, (6, 3, 3)), (2, 2), (ku, [0, 0, 0, 1, 1, 1]))
    face = TrimmedFace(s, None, None, (0.6, 1.4, 0.0, 1.0), (1.0, None), False)
    t = sufficient_parameters(face, 0, 24)
    assert t[0] == 0.6 and t[-1] == 1.4 and np.all(np.diff(t) > 0)
    assert np.isin([0.75, 1.0, 1.25], t).all() and len(t) == 4 * 3 + 1


def test_parameters_a_tolerance_past_the_knots_belong_to_the_end_span(rng):
    s = sm.BSplineSurface(rng.uniform(-1, 1, (4, 4, 3)), (3, 3))
    from surfmod.readback import TrimmedFace

    face = TrimmedFace(s, None, None, (-1e-6, 1.0 + 1e-6, 0.0, 1.0), (None, None), False)
    np.testing.assert_allclose(sufficient_parameters(face, 0, 24), np.linspace(-1e-6, 1 + 1e-6, 5), rtol=0, atol=1e-15)


class _WideCylinder(sm.CylindricalSurface):
    """OCCT twin with the radius 1e-9 larger."""

    def geom(self):
        return sm.CylindricalSurface(self.radius * (1 + 1e-9), self.origin, self.z_dir, self.x_dir,
                                     u_range=self.domain[0], v_range=self.domain[1]).geom()


def test_sufficient_sampling_fails_a_wrong_elementary_twin():
    s = _WideCylinder(100.0, (0, 0, 0), (0, 0, 1), v_range=(0, 5))
    r = sm.crosscheck(s, samples=24, sampling="sufficient")
    assert not r.passed and "position_rel" in r.details["failed"]
    assert r.max_deviation == pytest.approx(1e-7, rel=1e-3) and r.samples == 25


class _OnePoleOff(sm.BSplineSurface):
    """OCCT twin with one interior pole moved by 1e-9: a disagreement on a few spans only."""

    def geom(self):
        net = np.array(self.control_points)
        net[5, 3, 2] += 1e-9
        return sm.BSplineSurface._trusted(net, self.degree, self.knots).geom()


def test_sufficient_sampling_fails_a_local_disagreement(rng):
    net = rng.uniform(-1, 1, (9, 7, 3))
    s = _OnePoleOff._trusted(net, (3, 3), sm.BSplineSurface(net, (3, 3)).knots)
    r = sm.crosscheck(s, samples=24, sampling="sufficient")
    assert r.samples < 24 * 24
    assert not r.passed and r.details["position"] > 1e-11


class _BentD1(sm.BSplineSurface):
    """First v-derivative off by 1e-6 of its size: positions agree exactly."""

    def _derivatives(self, u, v, order):
        out = np.array(super()._derivatives(u, v, order))
        out[:, 0, 1] *= 1 + 1e-6
        return out


def test_sufficient_sampling_fails_a_wrong_derivative(rng):
    net = rng.uniform(-1, 1, (4, 4, 3))
    s = _BentD1._trusted(net, (3, 3), sm.BSplineSurface(net, (3, 3)).knots)
    r = sm.crosscheck(s, samples=24, sampling="sufficient")
    assert r.samples == 25 and r.max_deviation < 1e-14
    assert not r.passed and "d1_rel" in r.details["failed"]


def test_a_batch_gives_each_face_its_own_figures(rng):
    """Faces of very different size and one failing surface in one batch: each result is
    the one ``crosscheck`` gives alone, bit for bit."""
    import build123d as bd

    net = rng.uniform(-1, 1, (4, 4, 3))
    objs = [
        sm.sphere(1e3),
        _OnePoleOff._trusted(rng.uniform(-1, 1, (9, 7, 3)), (3, 3), sm.BSplineSurface(rng.uniform(-1, 1, (9, 7, 3)), (3, 3)).knots),
        *bd.Cylinder(1e-3, 2e-3).faces(),
        sm.BSplineSurface(net, (3, 3), weights=rng.uniform(0.5, 2, (4, 4))),
    ]
    for sampling in ("dense", "sufficient"):
        many = crosscheck_many(objs, 9, sampling=sampling)
        alone = [sm.crosscheck(o, samples=9, sampling=sampling) for o in objs]
        assert [r.passed for r in many] == [True, False, True, True, True, True]
        for a, b in zip(many, alone):
            assert tuple(a) == tuple(b)
            assert {k: v for k, v in a.details.items() if k != "failed"} == {k: v for k, v in b.details.items() if k != "failed"}


def test_a_batch_returns_the_error_of_an_unreadable_object():
    out = crosscheck_many([sm.sphere(1.0), "not a face", sm.BSplineCurve(np.eye(3), 2)], 4)
    assert out[0].passed and out[2].passed
    assert isinstance(out[1], sm.SurfmodError) and "face" in str(out[1])


def test_batches_are_bounded(monkeypatch):
    """More faces than one batch holds: every face is judged, in pieces."""
    import surfmod.occt_crosscheck as v

    monkeypatch.setattr(v, "BATCH_FACES", 2)
    objs = [sm.sphere(1.0 + i) for i in range(5)] + [_WideCylinder(100.0, v_range=(0, 5))]
    out = crosscheck_many(objs, 6, sampling="sufficient")
    assert [r.passed for r in out] == [True] * 5 + [False]
    assert [r.max_deviation for r in out] == [sm.crosscheck(o, 6, sampling="sufficient").max_deviation for o in objs]


def test_sampling_must_be_named():
    with pytest.raises(sm.SurfmodError, match="sampling"):
        sm.crosscheck(sm.sphere(1.0), sampling="sparse")


def _check_agrees_with_the_dense_check(path):
    """``check_file``'s rows = the dense per-face crosscheck: the same verdicts, deviations
    within 1e-13 of the face size."""
    from surfmod.cli.check import check_file
    from surfmod.occ.topo import faces_of

    rows = check_file(path, 24)
    faces = faces_of(sm.import_step(path))
    assert len(rows) == len(faces)
    for row, face in zip(rows, faces):
        dense = sm.crosscheck(face, samples=24)
        assert row[4] == dense.passed
        scale = dense.details["position"] / dense.details["position_rel"] if dense.details["position"] else 1.0
        assert abs(row[3] - dense.max_deviation) <= 1e-13 * scale


def test_check_file_agrees_with_the_dense_check():
    _check_agrees_with_the_dense_check(CORPUS / "occt_linkrods.step")


@pytest.mark.corpus
def test_check_file_agrees_with_the_dense_check_on_the_corpus(judged_file):
    _check_agrees_with_the_dense_check(judged_file)
