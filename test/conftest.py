"""Shared pytest set-up: DDS isolation for every test run (helpers live in ``support``)."""

import os
import random

# Two test runs on one domain cross-talk (ENVIRONMENT.md): every run gets its own random domain,
# discovery limited to this host, and the only RMW the PyPI wheels ship.
os.environ.pop('RMW_IMPLEMENTATION', None)
os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
