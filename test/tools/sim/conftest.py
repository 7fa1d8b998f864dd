"""Fixtures of the simulator tests: scenarios of every kind, made once per test run."""

from baseball_collision.tools.sim import KINDS, make_scenario
import numpy as np
import pytest

SEEDS = range(20)


@pytest.fixture(scope='session')
def scenarios() -> dict:
    """Twenty scenarios of every kind (seeds 0-19)."""
    return {kind: [make_scenario(kind, np.random.default_rng(seed)) for seed in SEEDS]
            for kind in KINDS}
