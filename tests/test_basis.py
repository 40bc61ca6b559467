"""Basis functions against the recursive Cox-de Boor and Bernstein formulas."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import reference as ref
from strategies import clamped_knots
from surfmod.eval.basis import (basis_derivatives, basis_matrix, clamped_bezier_knots, find_spans, reciprocal_table,
                                 span_buckets)


@settings(max_examples=40, deadline=None)
@given(p=st.integers(1, 7), extra=st.integers(0, 5), data=st.data())
def test_basis_matches_cox_de_boor(p, extra, data):
    n = p + 1 + extra
    knots = data.draw(clamped_knots(n, p))
    t = np.unique(np.concatenate([np.linspace(knots[p], knots[n], 9), knots[p : n + 1]]))
    mat = basis_matrix(knots, p, n, t)[0]
    expected = np.array([ref.bspline_basis(knots, p, n, x) for x in t])
    np.testing.assert_allclose(mat, expected, atol=1e-12)
    np.testing.assert_allclose(mat.sum(axis=1), 1.0, atol=1e-13)  # partition of unity


@pytest.mark.parametrize("degree", [1, 2, 5, 12, 25])
def test_bernstein_basis(degree):
    t = np.linspace(0, 1, 31)
    mat = basis_matrix(clamped_bezier_knots(degree), degree, degree + 1, t)[0]
    expected = np.array([[ref.bernstein(i, degree, x) for i in range(degree + 1)] for x in t])
    np.testing.assert_allclose(mat, expected, atol=1e-13)


@settings(max_examples=30, deadline=None)
@given(p=st.integers(1, 6), extra=st.integers(0, 4), data=st.data())
def test_basis_derivatives_match_finite_differences(p, extra, data):
    n = p + 1 + extra
    knots = data.draw(clamped_knots(n, p))
    breaks = np.unique(knots[p : n + 1])
    # interior points of spans, away from knots where derivatives jump
    t = (breaks[:-1] + breaks[1:]) / 2
    spans = find_spans(knots, p, n, t)
    ders = basis_derivatives(knots, p, spans, t, 2)
    h = 1e-6 * (knots[n] - knots[p])
    for k in (1, 2):
        lo = basis_derivatives(knots, p, spans, t - h, k - 1)[:, k - 1]
        hi = basis_derivatives(knots, p, spans, t + h, k - 1)[:, k - 1]
        fd = (hi - lo) / (2 * h)
        scale = max(1.0, np.abs(ders[:, k]).max())
        np.testing.assert_allclose(ders[:, k], fd, atol=2e-4 * scale)


def test_derivatives_above_degree_are_zero():
    knots = clamped_bezier_knots(2)
    t = np.linspace(0, 1, 5)
    ders = basis_derivatives(knots, 2, find_spans(knots, 2, 3, t), t, 4)
    assert np.all(ders[:, 3:] == 0.0)
    # second derivative of Bernstein quadratics: (2, -4, 2)
    np.testing.assert_allclose(ders[:, 2], np.tile([2.0, -4.0, 2.0], (5, 1)))


def test_span_at_domain_end_is_last_nonempty():
    knots = np.array([0, 0, 0, 0.5, 1, 1, 1.0])
    assert find_spans(knots, 2, 4, np.array([1.0]))[0] == 3
    assert find_spans(knots, 2, 4, np.array([0.5]))[0] == 3
    assert find_spans(knots, 2, 4, np.array([0.0]))[0] == 2


@settings(max_examples=40, deadline=None)
@given(p=st.integers(1, 7), extra=st.integers(0, 6), data=st.data())
def test_compiled_basis_derivatives_match_textbook(p, extra, data):
    """The division-free kernel (reciprocal knot differences, degree raising) against the
    textbook derivative formula applied recursively, on knots, at both ends and between."""
    from surfmod.eval import kernels

    n = p + 1 + extra
    knots = data.draw(clamped_knots(n, p))
    t = np.unique(np.concatenate([np.linspace(knots[p], knots[n], 7), knots[p : n + 1]]))
    order = p + 1
    inv = reciprocal_table(knots, p, n)
    scratch = (np.empty((p + 1, p + 1)), np.empty(p + 1), np.empty(p + 1), np.empty(p + 1))
    ders = np.empty((order + 1, p + 1))
    bucket = span_buckets(knots, p, n)
    for x in t:
        span = kernels.find_span_bucketed(knots, p, n, x, *bucket)
        assert span == find_spans(knots, p, n, np.array([x]))[0]
        kernels.basis_ders_point(knots, p, span, x, order, inv, scratch[0], scratch[1], scratch[2], scratch[3], ders)
        for k in range(order + 1):
            full = np.zeros(n)
            full[span - p : span + 1] = ders[k]
            expected = ref.bspline_basis_derivative(knots, p, n, x, k)
            scale = max(1.0, np.abs(expected).max())
            np.testing.assert_allclose(full, expected, rtol=0, atol=1e-13 * scale, err_msg=f"order {k} at {x}")
