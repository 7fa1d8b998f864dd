"""
A short fault-injection soak of the live impact_node: ``support.faults`` over ``support.soak``.

A real node process, 250 Hz per stream (low enough that a loaded machine keeps up outside the
burst), reliable QoS, issue 12's faults in turn with good pitches between: a stale second ball
publisher, lone stamp glitches before contacts, a dead bat stream, a burst of 2,500 messages.
Asserted is what does not depend on the machine's speed: the node survives, every contact
outside the dead-bat and burst seconds is found (the stale publisher's and the glitched ones
too), no impact is invented, nothing resets, every injected fault is counted by its drop
reason, and messages lost show in the diagnostics. The figures are the benchmark's
(``benchmarks/bench_faults.py``).
"""

import pytest
from support.faults import false_impacts, FaultPlan, losses, PITCH_GAP_NS
from support.soak import run_soak

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SECONDS = 30.0
RATE_HZ = 250.0


def test_faults_in_turn_at_250_hz() -> None:
    """Every good contact found, none invented, no reset, faults counted, losses reported."""
    plan = FaultPlan(SECONDS, RATE_HZ, burst_frames=1250)
    soak = run_soak(SECONDS, RATE_HZ, injector=plan, gap_ns=PITCH_GAP_NS)
    print('\n' + soak.report())
    assert soak.frames == int(SECONDS * RATE_HZ)
    assert plan.injected['stale'] > 500 and plan.injected['glitches'] >= 8
    assert len(soak.expected) > 40 and soak.lost == [], soak.lost
    false, _ = false_impacts(soak, plan)
    assert false == []
    assert soak.node['resets'] == 0
    loss = losses(soak, plan)
    received_stale = soak.node['dropped'].get('stale_stamp', 0)
    assert 0 < received_stale <= plan.injected['stale']
    assert soak.node['dropped'].get('stamp_ahead', 0) <= plan.injected['glitches']
    assert set(soak.node['dropped']) <= {'stale_stamp', 'stamp_ahead'}
    assert loss.received == soak.node['received']  # the last status came after everything
    if loss.lost:  # messages lost (the stale publisher's too): the node said so
        assert loss.reported > 0 and any(int(v['lost_in_period']) for v in soak.diagnostics)
    else:
        assert loss.reported == 0
