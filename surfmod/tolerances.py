"""The few named tolerances of surfmod, documented once.

``EXACT_RTOL``
    Relative agreement expected between the NumPy evaluator and OCCT for constructs
    that OCCT represents exactly (relative to the size of the control net).
``DERIVATIVE_RTOL``
    The same for first and second derivatives, which lose a few digits to cancellation
    in the de Boor recurrences of both implementations.
``DEGENERATE_NORMAL``
    ``|Su x Sv|`` below this fraction of ``|Su| |Sv|`` (or of the net size squared)
    marks a degenerate point (collapsed edge, pole) whose normal is taken as the limit
    from the inside of the domain.
``GEOMETRIC_TOL``
    Default pass threshold of the geometric cross-check for constructs OCCT only
    approximates (sweeps, lofts, fits), in model units.
``CROSSCHECK_POSITION_RTOL``
    Pass limit of the parametric cross-check on positions, relative to the size of the
    geometry: both evaluators round at ``EXACT_RTOL``; a tenfold margin covers the
    different summation orders (de Boor vs. power-basis cache).
``CROSSCHECK_NORMAL_RTOL``
    Pass limit on the normal deviation converted back into the derivative difference
    that explains it (see ``occt_crosscheck._normal_turns``): derivatives agree to about
    ``DERIVATIVE_RTOL``; the cross product and normalization lose up to two digits more.
``CROSSCHECK_CURVATURE_RTOL``
    Pass limit on curvatures relative to the largest curvature: curvature divides
    second derivatives by ``|Su x Sv|`` (cubed for the Gaussian), losing about three
    digits against the derivatives themselves.
``MASS_AGREEMENT_RTOL``
    Relative volume agreement ``surfmod mass`` demands between its quadrature and
    ``BRepGProp`` at eps 1e-9; beyond it the command says whether the model's own
    boundary ambiguity explains the difference, and exits non-zero either way.
``SHORT_SPAN_RTOL``
    Knot spans narrower than this fraction of the parameter domain are round-off, not
    geometry (files from other systems carry spans ~1e-11 wide): derivatives there grow
    like ``h^-k`` and curvature means nothing, so the cross-check judges only positions
    on them and says how many samples it judged so.
"""

EXACT_RTOL = 1e-12
DERIVATIVE_RTOL = 1e-10
DEGENERATE_NORMAL = 1e-10
GEOMETRIC_TOL = 1e-4
CROSSCHECK_POSITION_RTOL = 10 * EXACT_RTOL
CROSSCHECK_NORMAL_RTOL = 1e-8
CROSSCHECK_CURVATURE_RTOL = 1e-7
SHORT_SPAN_RTOL = 1e-9
MASS_AGREEMENT_RTOL = 1e-7


def occt_derivative_rtol(degree: int) -> float:
    """Relative tolerance for comparing derivatives with OCCT's ``D1``/``D2`` at ``degree``.

    OCCT evaluates spline derivatives from a power-basis cache around the span start; for
    high degrees it loses digits towards the span end (pinned in
    ``tests/test_occt_quirks.py``: degree 16 about 1e-10, degree 25 about 1e-6 relative,
    while positions from ``Value`` stay exact).  Up to degree 12 the plain
    ``DERIVATIVE_RTOL`` holds; above, the bound grows half a decade per degree.
    """
    return DERIVATIVE_RTOL * 10.0 ** (0.5 * max(0, degree - 12))
