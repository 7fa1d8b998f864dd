"""Shared pytest set-up: the repository root, and DDS isolation for every test run."""

import os
from pathlib import Path
import random

REPO_ROOT = Path(__file__).resolve().parent.parent

# Two test runs on one domain cross-talk (ENVIRONMENT.md): every run gets its own random domain,
# discovery limited to this host, and the only RMW the PyPI wheels ship.
os.environ.pop('RMW_IMPLEMENTATION', None)
os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')


def examples(count: int) -> int:
    """Scale a property test's example count: `HYPOTHESIS_SCALE=20 make test` runs 20x more."""
    return max(1, int(count * float(os.environ.get('HYPOTHESIS_SCALE', '1'))))
