"""Shared test configuration: hypothesis profile and seeded generators."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# Numba compiles on first call and the CI machine is shared: no per-example deadline.
settings.register_profile("default", deadline=None, max_examples=40,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", deadline=None, max_examples=400,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


@pytest.fixture
def rng():
    """A fresh, seeded generator per test (results reproducible from the seed)."""
    return np.random.default_rng(20261121)
