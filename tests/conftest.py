"""Shared fixtures for the surfmod tests.

Hypothesis runs derandomized, so every run of the README's test command (CI's included)
checks the same examples and a failure reproduces.  To explore new random examples, run
with ``HYPOTHESIS_PROFILE=explore``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

settings.register_profile("reproducible", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "reproducible"))


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# The real-parts corpus (tests/data/step, each file's origin and licence in its SOURCES.md).
# Tests over every file of it are marked ``corpus`` and run as the second command of .ci/run:
# ``python -m pytest -q -m corpus``; the default run (``-m "not corpus"`` in pyproject)
# keeps the quick per-file cases.
CORPUS = Path(__file__).resolve().parent / "data" / "step"
CORPUS_FILES = sorted(p for p in CORPUS.glob("*") if p.suffix.lower() in (".step", ".stp"))


# An empty corpus must fail, not skip: with no params pytest would skip every corpus test.
@pytest.fixture(params=CORPUS_FILES or [None], ids=lambda p: p.name if p else "missing")
def corpus_file(request):
    """Each STEP file of the real-parts corpus in turn."""
    if request.param is None:
        pytest.fail(f"the real-parts corpus is missing: {CORPUS}")
    return request.param


@pytest.fixture(scope="session")
def corpus_dir():
    if not CORPUS_FILES:
        pytest.fail(f"the real-parts corpus is missing: {CORPUS}")
    return CORPUS
