"""Input checks done once, at the door of every public entry.

One validator per kind of argument (numbers, counts, points, parameter arrays, paths,
STEP files, surfaces and curves, the cost of a piece of work against its cap), each
raising :class:`~surfmod.errors.SurfmodError` whose message starts with the argument's
name; arrays come back as float64.  Inside the package the values are trusted.

The limits are documented once, in :doc:`/errors` (section "Limits, and the keyword that
raises each"): :data:`LARGEST` (``1e70``: curvature multiplies four first derivatives, so
fourth powers of such numbers stay finite in float64), :data:`MAX_DERIVATIVE_ORDER`,
:data:`MAX_POINTS`, :data:`MAX_PATH_COMPONENT` and :data:`MAX_PATH`.
"""

from __future__ import annotations

import math
import mmap
import os
import re
from pathlib import Path

import numpy as np

from .errors import DamagedFileError, SurfmodError

LARGEST = 1e70
MAX_DERIVATIVE_ORDER = 20
MAX_POINTS = 10_000_000
MAX_PATH_COMPONENT = 255
MAX_PATH = 4096


def frozen(array: np.ndarray) -> np.ndarray:
    """Return a read-only copy of ``array`` (the immutable-value rule)."""
    out = np.array(array, dtype=float, copy=True)
    out.setflags(write=False)
    return out


def _as_floats(value, name: str) -> np.ndarray:
    """``value`` as a float64 array; text, complex numbers, ragged lists, objects that are
    not numbers and integers beyond float range are refused."""
    if isinstance(value, (str, bytes)):
        raise SurfmodError(f"{name}: expected numbers, got {type(value).__name__} {value!r:.40}")
    try:
        raw = np.asarray(value)
        if raw.dtype.kind in "USVc" or (raw.dtype.kind == "O" and any(isinstance(x, (str, bytes, complex)) for x in raw.flat)):
            raise TypeError(f"{raw.dtype.kind == 'c' and 'complex' or 'text'} values")
        arr = np.asarray(raw, dtype=float)
    except OverflowError:
        raise SurfmodError(f"{name}: a number is too large (limit {LARGEST:g})") from None
    except (TypeError, ValueError) as exc:
        kind = "ragged nested lists" if "inhomogeneous" in str(exc) or "sequence" in str(exc) else str(exc)
        raise SurfmodError(f"{name}: expected numbers, got {type(value).__name__} ({kind})") from None
    return arr


def finite_array(value, name: str, *, ndim: int | None = None, last: int | None = None) -> np.ndarray:
    """``value`` as a finite float array of magnitude at most ``LARGEST``, optionally with
    ``ndim`` axes and last axis ``last``.

    >>> finite_array([[1, 2], [3]], "u")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: u: expected numbers, got list (ragged nested lists)
    """
    arr = _as_floats(value, name)
    if ndim is not None and arr.ndim != ndim:
        raise SurfmodError(f"{name}: expected an array with {ndim} axes, got shape {arr.shape}")
    if last is not None and (arr.ndim == 0 or arr.shape[-1] != last):
        raise SurfmodError(f"{name}: last axis must have length {last}, got shape {arr.shape}")
    _finite_range(arr, name)
    return arr


def _finite_range(arr: np.ndarray, name: str):
    """``(min, max)`` of a non-empty ``arr`` (None for an empty one) after refusing NaN,
    infinities and magnitudes above ``LARGEST``.  Min and max propagate NaN and expose
    infinities: two passes over the data and no temporary arrays."""
    if not arr.size:
        return None
    lo, hi = arr.min(), arr.max()
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise SurfmodError(f"{name}: contains NaN or infinite values")
    if max(-lo, hi) > LARGEST:
        raise SurfmodError(f"{name}: magnitude {max(-lo, hi):.3g} exceeds the limit {LARGEST:g}")
    return lo, hi


def real(value, name: str, *, low: float | None = None, high: float | None = None) -> float:
    """One finite number (not an array) with optional inclusive bounds.

    >>> real(2, "twist")
    2.0
    >>> real([1, 2], "twist")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: twist: expected a single number, got an array of shape (2,)
    """
    if isinstance(value, bool):
        raise SurfmodError(f"{name}: expected a number, got {value!r}")
    arr = _as_floats(value, name)
    if arr.shape != ():
        raise SurfmodError(f"{name}: expected a single number, got an array of shape {arr.shape}")
    x = float(arr)
    if not math.isfinite(x):
        raise SurfmodError(f"{name}: must be finite, got {x}")
    if abs(x) > LARGEST:
        raise SurfmodError(f"{name}: {x:.3g} exceeds the limit {LARGEST:g} in magnitude")
    if low is not None and x < low:
        raise SurfmodError(f"{name}: must be >= {low:g}, got {x:g}")
    if high is not None and x > high:
        raise SurfmodError(f"{name}: must be <= {high:g}, got {x:g}")
    return x


def angle(value, name: str) -> float:
    """One finite angle (a single number, never an array)."""
    return real(value, name)


def point(value, name: str) -> np.ndarray:
    """A single 3-D point or vector."""
    arr = finite_array(value, name)
    if arr.shape != (3,):
        raise SurfmodError(f"{name}: expected 3 coordinates, got shape {arr.shape}")
    return arr


def direction(value, name: str) -> np.ndarray:
    """A unit 3-D direction; a zero-length vector is refused.  The norm is taken after
    scaling by the largest component, so huge vectors do not overflow to inf.

    >>> direction((1e300, 1e300, 1e300), "axis")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: axis: magnitude 1e+300 exceeds the limit 1e+70
    """
    vec = point(value, name)
    big = float(np.abs(vec).max())
    if big == 0.0 or big * np.linalg.norm(vec / big) < 1e-12:
        raise SurfmodError(f"{name}: zero-length direction")
    scaled = vec / big
    return scaled / np.linalg.norm(scaled)


def positive(value, name: str) -> float:
    """A finite number > 0 (a single number, at most ``LARGEST``)."""
    x = real(value, name)
    if x <= 0.0:
        raise SurfmodError(f"{name}: must be a finite number > 0, got {value!r}")
    return x


#: tolerances below this fraction of the model size are round-off, not a request: refused
TOLERANCE_FLOOR = 1e-12


def tolerance(value, name: str, size: float) -> float:
    """A tolerance for a model of size ``size`` (its bounding-box diagonal): a finite
    number within ``[TOLERANCE_FLOOR * size, size]``.  Below the floor no double-precision
    answer can be judged (iterations meant to reach it never stop); above the model size
    every answer is within it.  ``size <= 0`` (a degenerate model) checks only ``> 0``.

    >>> tolerance(1e-3, "tolerance", 10.0)
    0.001
    >>> tolerance(1e-300, "tolerance", 10.0)
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: tolerance: 1e-300 is below the floor 1e-11 (1e-12 of the model size 10)
    """
    tol = positive(value, name)
    size = float(size)
    if not (math.isfinite(size) and size > 0.0):
        return tol
    if tol < TOLERANCE_FLOOR * size:
        raise SurfmodError(f"{name}: {tol:g} is below the floor {TOLERANCE_FLOOR * size:g} "
                           f"({TOLERANCE_FLOOR:g} of the model size {size:g})")
    if tol > size:
        raise SurfmodError(f"{name}: {tol:g} exceeds the model size {size:g} (every answer would be within it)")
    return tol


def interval(value, name: str) -> tuple[float, float]:
    """A parameter or coordinate range ``(start, end)`` with finite ``start < end``.

    >>> interval([0, 2.5], "x_range")
    (0.0, 2.5)
    """
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise SurfmodError(f"{name}: expected two numbers (start, end), got {value!r:.60}")
    a, b = real(value[0], f"{name}[0]"), real(value[1], f"{name}[1]")
    if not b > a:
        raise SurfmodError(f"{name}: expected finite start < end, got ({a:g}, {b:g})")
    return a, b


def count(value, name: str, minimum: int = 1, maximum: int | None = None) -> int:
    """An integer in ``[minimum, maximum]``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise SurfmodError(f"{name}: expected an integer, got {value!r:.60}")
    if value < minimum:
        raise SurfmodError(f"{name}: must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        shown = f"{value}" if abs(value) < 10**30 else f"about 1e{len(str(abs(value))) - 1}"
        raise SurfmodError(f"{name}: must be <= {maximum}, got {shown}")
    return int(value)


def derivative_order(value, name: str = "order") -> int:
    """A derivative order ``0 <= order <= MAX_DERIVATIVE_ORDER``.

    >>> derivative_order(10**20)
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: order: must be <= 20, got 100000000000000000000
    """
    return count(value, name, minimum=0, maximum=MAX_DERIVATIVE_ORDER)


def work(estimate: float, cap: int, keyword: str, what: str) -> None:
    """Refuse a piece of work whose up-front estimate exceeds its cap.

    The message names the keyword that raises the cap, so the caller knows what to do.

    >>> work(5e7, 10_000_000, "max_points", "the grid of 5000 x 10000 points")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: max_points: the grid of 5000 x 10000 points needs about 50,000,000 points, above the cap 10,000,000; pass max_points= a larger value to allow it
    """
    cap = count(cap, keyword, minimum=1)
    try:
        estimate = float(estimate)
    except OverflowError:  # an exact integer product beyond float range
        estimate = math.inf
    if not estimate <= cap:
        unit = keyword.removeprefix("max_")
        shown = f"{estimate:,.0f}" if math.isfinite(estimate) else "more than 1e308"
        raise SurfmodError(
            f"{keyword}: {what} needs about {shown} {unit}, above the cap {cap:,}; "
            f"pass {keyword}= a larger value to allow it"
        )


def file_path(value, name: str = "path") -> Path:
    """A file path of a usable length (no OSError "File name too long" later).

    >>> file_path("a" * 300 + ".step", "path")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: path: file name of 305 bytes is longer than the limit 255
    """
    try:
        p = Path(os.fspath(value))
    except TypeError:
        raise SurfmodError(f"{name}: expected a file path, got {type(value).__name__}") from None
    text = str(p)
    if not text or text == ".":
        raise SurfmodError(f"{name}: empty file path")
    if "\x00" in text:
        raise SurfmodError(f"{name}: file path contains a NUL character")
    encoded = os.fsencode(text)
    if len(encoded) > MAX_PATH:
        raise SurfmodError(f"{name}: path of {len(encoded)} bytes is longer than the limit {MAX_PATH}")
    for part in p.parts:
        size = len(os.fsencode(part))
        if size > MAX_PATH_COMPONENT:
            raise SurfmodError(f"{name}: file name of {size} bytes is longer than the limit {MAX_PATH_COMPONENT}")
    return p


#: a list element that reads as no number within :data:`LARGEST`: NaN and infinity as C
#: libraries print them, and reals of an exponent of 70 or more (the pass below keeps those
#: that still fit).  OCCT 8.0's reader loops on a control point of ``inf`` or ``1.E308``
#: (over 240 s where the file reads in 3 s), so such numbers never reach it.
_NOT_A_NUMBER = (rb"[(,]\s*[-+]?(?:nan|inf(?:inity)?|\d+\.#\w+|\d*\.?\d*e\+?0*(?:[7-9]\d|[1-9]\d\d+))"
                 rb"\s*(?=[,)])")
_SUSPECT = re.compile(_NOT_A_NUMBER, re.IGNORECASE)
#: the same with strings and comments matched first, so a name such as 'a,inf,b' is skipped
_TOKENS = re.compile(rb"'(?:[^']|'')*'|/\*.*?\*/|" + _NOT_A_NUMBER, re.IGNORECASE | re.DOTALL)


def _out_of_range(token: bytes) -> bool:
    """Whether a token :data:`_NOT_A_NUMBER` matched is NaN, infinite or beyond :data:`LARGEST`."""
    try:
        return not abs(float(token)) <= LARGEST
    except ValueError:  # '1.#QNAN' and the like
        return True


def step_file(value, name: str = "path") -> Path:
    """An existing STEP file whose text OCCT can be given: a STEP header, and no number
    that is NaN, infinite or beyond :data:`LARGEST` (:class:`~surfmod.errors.DamagedFileError`
    naming the file).

    >>> import tempfile
    >>> bad = Path(tempfile.mkdtemp()) / "p.step"
    >>> _ = bad.write_bytes(b"ISO-10303-21;\\nDATA;\\n#1=CARTESIAN_POINT('',(0.,nan,1.));\\nENDSEC;")
    >>> step_file(bad)
    Traceback (most recent call last):
    ...
    surfmod.errors.DamagedFileError: path: ... has a number that is NaN, infinite or beyond 1e+70 ('nan' at byte 46)
    """
    p = file_path(value, name)
    if not p.is_file():
        raise SurfmodError(f"{name}: no such file {p}")
    try:
        with open(p, "rb") as fh:
            if b"ISO-10303-21" not in fh.read(256):
                raise SurfmodError(f"{name}: {p} is not a STEP file (not a readable STEP header: ISO-10303-21 missing)")
            with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as text:
                # one pass in C over the whole file; the string-aware pass only where it hit
                if _SUSPECT.search(text):
                    for m in _TOKENS.finditer(text):
                        token = m.group()[1:].strip()
                        if m.group().startswith((b"(", b",")) and _out_of_range(token):
                            token = token.decode("ascii")
                            raise DamagedFileError(f"{name}: {p} has a number that is NaN, infinite or beyond "
                                                   f"{LARGEST:g} ({token!r} at byte {m.start() + 1})")
    except OSError as exc:
        raise SurfmodError(f"{name}: cannot read {p} ({exc.strerror})") from None
    return p


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
    t = _as_floats(value, name)
    lo, hi = domain
    span = hi - lo
    if not t.size:
        return t.copy()
    t_lo, t_hi = _finite_range(t, name)
    if t_lo < lo - slack * span or t_hi > hi + slack * span:
        raise SurfmodError(
            f"{name}: parameters must lie in [{lo:g}, {hi:g}], got range [{t_lo:g}, {t_hi:g}]"
        )
    if t_lo >= lo and t_hi <= hi:  # already inside: no copy (evaluation only reads it)
        return t
    return np.clip(t, lo, hi)


def parameter_pair(u, v, domain, names=("u", "v"), per_point: int = 1, max_points: int = MAX_POINTS):
    """``(shape, u, v)``: validated parameters broadcast together and flattened.

    Refuses arrays that do not broadcast and broadcasts whose result
    (``per_point`` vectors each) would exceed ``max_points``.

    >>> parameter_pair(np.zeros(2), np.zeros(3), ((0, 1), (0, 1)))
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: u, v: shapes (2,) and (3,) do not broadcast together
    """
    uu = parameters(u, names[0], domain[0])
    vv = parameters(v, names[1], domain[1])
    try:
        shape = np.broadcast_shapes(uu.shape, vv.shape)
    except ValueError:
        raise SurfmodError(f"{names[0]}, {names[1]}: shapes {uu.shape} and {vv.shape} do not broadcast together") from None
    work(float(np.prod(shape, dtype=float)) * per_point, max_points, "max_points", f"evaluating {shape} parameters")
    uu, vv = np.broadcast_arrays(uu, vv)
    return shape, uu.ravel(), vv.ravel()


def parameter_grid(us, vs, domain, per_point: int = 1, max_points: int = MAX_POINTS):
    """``(us, vs)``: two flat validated parameter vectors for a tensor grid within the cap."""
    us = parameters(us, "us", domain[0]).ravel()
    vs = parameters(vs, "vs", domain[1]).ravel()
    work(float(us.size) * vs.size * per_point, max_points, "max_points", f"the grid of {us.size} x {vs.size} points")
    return us, vs
