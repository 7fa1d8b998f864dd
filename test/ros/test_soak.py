"""
A short soak of the live impact_node: the soak harness (``support.soak``) for 20 s.

A real node process, 1 kHz per stream, simulated pitches of every kind shifted in time,
reliable QoS. Asserted here is what does not depend on the machine's speed: every impact found
at its true instant, no false one, every message taken, no drop or reset, no warning. The
wall-clock figures (processing p99, memory growth, latency, backlog) are the benchmark's:
``benchmarks/bench_soak.py`` prints them and checks its limits.
"""

import pytest
from support.soak import run_soak

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SECONDS = 20.0


def test_twenty_seconds_at_one_kilohertz() -> None:
    """No lost or false impact, every message processed, no drop, reset or warning."""
    soak = run_soak(SECONDS)
    print('\n' + soak.report())
    assert soak.frames == int(SECONDS * 1000) and soak.published == 2 * soak.frames
    assert len(soak.expected) > 30 and soak.node['impacts'] == len(soak.impacts)
    assert soak.lost == [] and soak.false == [], (soak.lost, soak.false)
    assert soak.matched_error_us_max < 20.0
    assert sum(soak.node['received'].values()) == soak.published
    assert soak.node['dropped'] == {} and soak.node['resets'] == 0
    assert soak.node['count'] == soak.published  # every message went through the callback
    assert not soak.warnings, soak.warnings[:5]
