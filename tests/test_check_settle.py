"""A curvature disagreement between surfmod and OCCT is settled by a 40-digit evaluation
from the net (:mod:`surfmod.nets.mp_reference`) before the check decides who is wrong."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
import surfmod.occt_crosscheck as xc
from surfmod.nets import mp_reference


def _nurbs():
    rng = np.random.default_rng(0)
    net = rng.uniform(-1, 1, (6, 5, 3))
    net[..., 0] += np.arange(6)[:, None]
    net[..., 1] += np.arange(5)[None, :]
    ku = np.array([0, 0, 0, 0, 0.3, 0.3, 1, 1, 1, 1.0])  # 0.3 double: C1
    kv = np.array([0, 0, 0, 0.4, 0.6, 1, 1, 1.0])
    return sm.BSplineSurface(net, (3, 2), knots=(ku, kv), weights=rng.uniform(0.5, 2, (6, 5)))


def test_reference_curvatures_match_surfmod_and_occt():
    from surfmod.occ.sample import surface_props

    s = _nurbs()
    uv = np.random.default_rng(1).uniform(0, 1, (25, 2))
    _, k_occ = surface_props(s.geom(), uv[:, 0], uv[:, 1])
    for (u, v), ko in zip(uv, k_occ):
        ref = np.array(mp_reference.mp_curvatures(s.control_points, s.weights, s.degree, s.knots, u, v))
        c = s.curvatures(u, v)
        scale = max(1.0, np.abs(ref).max())
        np.testing.assert_allclose([c.gaussian, c.mean, c.k1, c.k2], ref, atol=1e-13 * scale, rtol=0)
        np.testing.assert_allclose(ko, ref, atol=1e-11 * scale, rtol=0)


def _occt_off(monkeypatch, factor):
    """OCCT's curvatures scaled by ``factor`` (the check imports surface_props per call)."""
    import surfmod.occ.sample as sample

    real = sample.surface_props

    def off(geom, u, v):
        n, k = real(geom, u, v)
        return n, k * factor

    monkeypatch.setattr(sample, "surface_props", off)


def test_occt_off_is_settled_in_surfmods_favour(monkeypatch):
    _occt_off(monkeypatch, 1 + 3e-6)  # as the ACIS part: OCCT's curvature 3e-6 relative off
    r = sm.crosscheck(_nurbs(), sampling="sufficient")
    assert r.passed, r.details["failed"]
    assert r.details["curvature_rel"] > 1e-7  # the disagreement is still reported
    assert r.details["curvature_settled"].startswith("surfmod right")


def test_surfmod_off_stays_a_failure(monkeypatch):
    real = xc.curvatures

    def off(ders):
        c = real(ders)
        return type(c)(*(x * (1 + 3e-6) for x in c))

    monkeypatch.setattr(xc, "curvatures", off)
    r = sm.crosscheck(_nurbs(), sampling="sufficient")
    assert not r.passed and "curvature_rel" in r.details["failed"]
    assert r.details["curvature_settled"].startswith("surfmod wrong")
