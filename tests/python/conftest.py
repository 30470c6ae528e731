"""pytest configuration: hypothesis profiles and shared fixtures."""
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# CI is derandomized so a run is reproducible; locally hypothesis explores.
settings.register_profile("ci", derandomize=True, deadline=None, max_examples=150,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, max_examples=150)
settings.load_profile("ci" if os.environ.get("CI") else "dev")


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
