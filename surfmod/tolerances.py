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
``LINEAR``
    Default modelling tolerance handed to OCCT builders (sewing, pipe shells).
"""

EXACT_RTOL = 1e-12
DERIVATIVE_RTOL = 1e-10
DEGENERATE_NORMAL = 1e-10
GEOMETRIC_TOL = 1e-4
LINEAR = 1e-7


def occt_derivative_rtol(degree: int) -> float:
    """Relative tolerance for comparing derivatives with OCCT's ``D1``/``D2`` at ``degree``.

    OCCT evaluates spline derivatives from a power-basis cache around the span start; for
    high degrees it loses digits towards the span end (pinned in
    ``tests/test_occt_quirks.py``: degree 16 about 1e-10, degree 25 about 1e-6 relative,
    while positions from ``Value`` stay exact).  Up to degree 12 the plain
    ``DERIVATIVE_RTOL`` holds; above, the bound grows half a decade per degree.
    """
    return DERIVATIVE_RTOL * 10.0 ** (0.5 * max(0, degree - 12))
