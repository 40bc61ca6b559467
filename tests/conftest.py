"""Shared fixtures for the surfmod tests.

Hypothesis runs derandomized, so every run of the README's test command (CI's included)
checks the same examples and a failure reproduces.  To explore new random examples, run
with ``HYPOTHESIS_PROFILE=explore``.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

settings.register_profile("reproducible", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "reproducible"))


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
