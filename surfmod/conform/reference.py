"""The 40-digit reference of the conformance cases, and its cache.

The values come from :mod:`surfmod.nets.mp_reference` (Cox–de Boor in ``mpmath``, no code
shared with any evaluator held against it), rounded once to float.  A point costs
milliseconds, so the reference of the stress and lecture cases is computed once and kept
in ``reference.npz`` beside this module, keyed by each case's fingerprint and stamped with
the mpmath version and the digits; a case whose fingerprint is not in the file (a STEP
face, a list of surfaces, a case changed since) is computed on the spot.  Regenerate the
file after changing the cases with::

    python -m surfmod.conform.reference
"""

from __future__ import annotations

import sys
from pathlib import Path

import mpmath as mp
import numpy as np
from tqdm import tqdm

from ..atomic import atomic_path
from ..nets import mp_reference
from .cases import Case, lecture_cases, stress_cases

#: the cache of the shipped cases
CACHE = Path(__file__).resolve().with_name("reference.npz")
#: decimal digits of the reference
DPS = 40

_loaded: dict | None = None


def compute(case: Case, dps: int = DPS) -> np.ndarray:
    """The reference partials of ``case`` to order 2: ``(N, 3, 3, 3)`` for a surface
    (``[a, k, l]``, NaN where ``k + l > 2``), ``(N, 3, 3)`` for a curve (``[a, k]``)."""
    o = case.obj
    if case.is_curve:
        return np.array([[[float(x) for x in d] for d in mp_reference.curve_partials(
            o.control_points, o.weights, o.degree, o.knots, t, dps)] for t in case.u]).reshape(-1, 3, 3)
    out = np.full((case.u.size, 3, 3, 3), np.nan)
    for a, (u, v) in enumerate(zip(case.u, case.v)):
        d = mp_reference.mp_partials(o.control_points, o.weights, o.degree, o.knots, u, v, dps)
        for (k, l), vec in d.items():
            out[a, k, l] = [float(x) for x in vec]
    return out


def _cache() -> dict:
    global _loaded
    if _loaded is None:
        _loaded = {}
        if CACHE.exists():
            with np.load(CACHE) as data:
                if int(data["dps"]) == DPS:
                    _loaded = {key[4:]: data[key] for key in data.files if key.startswith("ref_")}
    return _loaded


def reference(case: Case) -> np.ndarray:
    """:func:`compute` of ``case``, from the cache when it holds the case; a case computed
    here is kept for the rest of the process (a second evaluator held against the same
    STEP file does not pay for it again)."""
    key = case.fingerprint()
    if key not in _cache():
        _cache()[key] = compute(case)
    return _cache()[key]


def cached(case: Case) -> bool:
    """Whether the cache holds ``case`` (as it is now)."""
    return case.fingerprint() in _cache()


def regenerate(path: Path = CACHE, progress: bool = True) -> int:
    """Compute the reference of every stress and lecture case and write the cache
    (atomically); returns the number of cases."""
    cases = stress_cases() + lecture_cases()
    arrays = {f"ref_{c.fingerprint()}": compute(c) for c in tqdm(cases, desc="reference", disable=not progress)}
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, dps=DPS, mpmath_version=mp.__version__, **arrays)
    global _loaded
    _loaded = None
    return len(cases)


if __name__ == "__main__":  # pragma: no cover - the regeneration command
    print(f"{regenerate()} cases written to {CACHE} (mpmath {mp.__version__}, {DPS} digits)")
    sys.exit(0)
