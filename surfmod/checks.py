"""Input checks done once, at the door of every public constructor.

Each helper converts its argument to a float64 NumPy array (copied, read-only) and raises
:class:`~surfmod.errors.SurfmodError` naming the argument when the value is unusable.
Inside the package the arrays are trusted.
"""

from __future__ import annotations

import numpy as np

from .errors import SurfmodError


def frozen(array: np.ndarray) -> np.ndarray:
    """Return a read-only copy of ``array`` (the immutable-value rule)."""
    out = np.array(array, dtype=float, copy=True)
    out.setflags(write=False)
    return out


def finite_array(value, name: str, *, ndim: int | None = None, last: int | None = None) -> np.ndarray:
    """``value`` as a finite float array, optionally with ``ndim`` axes and last axis ``last``."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SurfmodError(f"{name}: expected numbers, got {type(value).__name__} ({exc})") from None
    if ndim is not None and arr.ndim != ndim:
        raise SurfmodError(f"{name}: expected an array with {ndim} axes, got shape {arr.shape}")
    if last is not None and (arr.ndim == 0 or arr.shape[-1] != last):
        raise SurfmodError(f"{name}: last axis must have length {last}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SurfmodError(f"{name}: contains NaN or infinite values")
    return arr


def point(value, name: str) -> np.ndarray:
    """A single 3-D point or vector."""
    arr = finite_array(value, name)
    if arr.shape != (3,):
        raise SurfmodError(f"{name}: expected 3 coordinates, got shape {arr.shape}")
    return arr


def direction(value, name: str) -> np.ndarray:
    """A unit 3-D direction; a zero-length vector is refused."""
    vec = point(value, name)
    norm = np.linalg.norm(vec)
    if norm < 1e-12:
        raise SurfmodError(f"{name}: zero-length direction")
    return vec / norm


def positive(value, name: str) -> float:
    """A finite float > 0."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected a number, got {value!r}") from None
    if not np.isfinite(x) or x <= 0.0:
        raise SurfmodError(f"{name}: must be a finite number > 0, got {value!r}")
    return x


def interval(value, name: str) -> tuple[float, float]:
    """A parameter or coordinate range ``(start, end)`` with finite ``start < end``.

    >>> interval([0, 2.5], "x_range")
    (0.0, 2.5)
    """
    try:
        a, b = (float(t) for t in value)
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected two numbers (start, end), got {value!r}") from None
    if not (np.isfinite(a) and np.isfinite(b)) or not b > a:
        raise SurfmodError(f"{name}: expected finite start < end, got ({a:g}, {b:g})")
    return a, b


def count(value, name: str, minimum: int = 1) -> int:
    """An integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise SurfmodError(f"{name}: expected an integer, got {value!r}")
    if value < minimum:
        raise SurfmodError(f"{name}: must be >= {minimum}, got {value}")
    return int(value)


def control_net(value, name: str = "control_points") -> np.ndarray:
    """An (n, m, 3) net of control points, n, m >= 2."""
    arr = finite_array(value, name, ndim=3, last=3)
    if arr.shape[0] < 2 or arr.shape[1] < 2:
        raise SurfmodError(f"{name}: need at least 2 x 2 control points, got shape {arr.shape}")
    return arr


def weights_for(value, shape: tuple[int, ...], name: str = "weights") -> np.ndarray | None:
    """Weights of the given shape, all finite and > 0 (None stays None)."""
    if value is None:
        return None
    arr = finite_array(value, name)
    if arr.shape != shape:
        raise SurfmodError(f"{name}: expected shape {shape}, got {arr.shape}")
    if np.any(arr <= 0.0):
        raise SurfmodError(f"{name}: all weights must be > 0 (min is {arr.min():g})")
    return arr


def knot_vector(value, degree: int, n_ctrl: int, name: str = "knots") -> np.ndarray:
    """A full knot vector for ``n_ctrl`` control points of ``degree``.

    Length n_ctrl + degree + 1, non-decreasing, no multiplicity above degree + 1, and a
    non-empty domain ``[k[p], k[n]]``.  Interior multiplicity is capped at ``degree``
    so that the curve stays continuous.
    """
    k = finite_array(value, name, ndim=1)
    expected = n_ctrl + degree + 1
    if k.size != expected:
        raise SurfmodError(
            f"{name}: expected {expected} knots for {n_ctrl} control points of degree {degree}, got {k.size}"
        )
    if np.any(np.diff(k) < 0):
        bad = int(np.argmax(np.diff(k) < 0))
        raise SurfmodError(f"{name}: must be non-decreasing (knot {bad + 1} = {k[bad + 1]:g} < {k[bad]:g})")
    values, counts = np.unique(k, return_counts=True)
    if counts.max() > degree + 1:
        raise SurfmodError(
            f"{name}: multiplicity {counts.max()} of knot {values[counts.argmax()]:g} exceeds degree + 1 = {degree + 1}"
        )
    lo, hi = k[degree], k[n_ctrl]
    if not hi > lo:
        raise SurfmodError(f"{name}: empty parameter domain [{lo:g}, {hi:g}]")
    inner = (values > lo) & (values < hi)
    if np.any(counts[inner] > degree):
        v = values[inner][counts[inner].argmax()]
        raise SurfmodError(f"{name}: interior knot {v:g} has multiplicity above the degree {degree}")
    return k


def degree(value, name: str, n_ctrl: int, maximum: int = 25) -> int:
    """A degree 1 <= p <= min(maximum, n_ctrl - 1)."""
    p = count(value, name, minimum=1)
    if p > maximum:
        raise SurfmodError(f"{name}: degree {p} exceeds the maximum {maximum}")
    if p > n_ctrl - 1:
        raise SurfmodError(f"{name}: degree {p} needs at least {p + 1} control points, got {n_ctrl}")
    return p


def parameters(value, name: str, domain: tuple[float, float], slack: float = 1e-9) -> np.ndarray:
    """Finite parameters inside ``domain`` (a little slack for round-off), clipped to it."""
    t = finite_array(value, name)
    lo, hi = domain
    span = hi - lo
    if t.size and (t.min() < lo - slack * span or t.max() > hi + slack * span):
        raise SurfmodError(
            f"{name}: parameters must lie in [{lo:g}, {hi:g}], got range [{t.min():g}, {t.max():g}]"
        )
    return np.clip(t, lo, hi)
