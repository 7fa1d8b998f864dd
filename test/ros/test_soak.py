"""
A short soak of the live impact_node: ``benchmarks/bench_soak.py`` for 20 s.

The benchmark's harness as it is (a real node process, 1 kHz per stream, simulated pitches of
every kind shifted in time, reliable QoS); the 10-minute figures are in the benchmark's output.
"""

import sys

import pytest
from support import REPO_ROOT

sys.path.insert(0, str(REPO_ROOT / 'benchmarks'))
from bench_soak import run_soak  # noqa: E402, I100 - the benchmarks folder is not a package

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SECONDS = 20.0


def test_twenty_seconds_at_one_kilohertz() -> None:
    """No lost or false impact, every message processed, no backlog, flat memory, fast."""
    soak = run_soak(SECONDS)
    print('\n' + soak.report())
    assert soak.frames == int(SECONDS * 1000) and soak.published == 2 * soak.frames
    assert len(soak.expected) > 30 and soak.node['impacts'] == len(soak.impacts)
    assert soak.lost == [] and soak.false == [], (soak.lost, soak.false)
    assert soak.matched_error_us_max < 20.0
    # no backlog: the node took every message, its watermark kept up, latency did not grow
    assert sum(soak.node['received'].values()) == soak.published
    assert soak.node['dropped'] == {} and soak.node['resets'] == 0
    assert soak.watermark_lag_max < 200
    first, last = soak.latency_tenths()
    assert max(soak.latencies_ms) < 500.0 and last < first + 20.0
    # the node: processing p99 within 1 ms, memory flat
    assert soak.node['p99'] <= 1.0, soak.node
    assert soak.growth_mb < 5.0, soak.rss_kb
    assert not soak.warnings, soak.warnings[:5]
