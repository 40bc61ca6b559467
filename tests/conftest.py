"""Shared fixtures for the surfmod tests.

Under CI (``CI`` set in the environment) hypothesis runs derandomized, so a run is
reproducible; locally it explores new examples each time.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
