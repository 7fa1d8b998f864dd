"""Shared pytest set-up: DDS isolation for every test run (helpers live in ``support``)."""

import os
import random

# Two test runs on one domain cross-talk (ENVIRONMENT.md): every run gets its own random domain,
# discovery limited to this host, and the only RMW the PyPI wheels ship.
os.environ.pop('RMW_IMPLEMENTATION', None)
os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
# Under pytest-xdist (`make test` runs one worker per core) each worker is a test run of its own:
# worker gwN takes the N+1st domain after the controller's (1-101, wrapping).
if os.environ.get('PYTEST_XDIST_WORKER', '').startswith('gw'):
    _worker = int(os.environ['PYTEST_XDIST_WORKER'][2:])
    os.environ['ROS_DOMAIN_ID'] = str((int(os.environ['ROS_DOMAIN_ID']) + _worker) % 101 + 1)
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
