"""The bundled bags, their rates and truth files, and the check of a report against truth."""

from pathlib import Path
from typing import Any, Dict

import pytest
from support import REPO_ROOT

BAGS = {
    'pitches_90hz.mcap': 90.0,
    'pitches_120hz_sqlite3': 120.0,
    'pitches_240hz_noisy.bag': 240.0,
    'pitches_360hz.mcap': 360.0,
    'pitches_180hz_rebound.mcap': 180.0,
    'pitches_1khz_arm.mcap': 60.0,
}
"""Bundled bags and their nominal rates (Hz; the arm's bag: its ball's, the slower stream)."""

PARAMS = REPO_ROOT / 'config' / 'impact_node.yaml'
SPOT_BOUND_M = 0.005
SPEED_BOUND = 0.02


def bag_path(name: str) -> Path:
    """Return a bundled bag's path."""
    return REPO_ROOT / 'bags' / name


def time_bound_ns(rate_hz: float) -> int:
    """Return the time error bound: 1 % of the frame period (ns)."""
    return int(0.01 / rate_hz * 1e9)


def check_against_truth(document: Dict[str, Any], truth: Dict[str, Any],
                        rate_hz: float) -> None:
    """Every true contact found within the bounds, no false impact, misses as near misses."""
    impacts = document['impacts']
    used = set()
    for pitch in truth['pitches']:
        inside = [i for i, impact in enumerate(impacts)
                  if pitch['start_ns'] <= impact['stamp_ns'] <= pitch['end_ns']]
        if not pitch['contact']:
            assert not inside, f"false impact in {pitch['name']}"
            continue
        assert len(inside) == 1, f"{pitch['name']}: {len(inside)} impacts"
        impact = impacts[inside[0]]
        used.add(inside[0])
        assert abs(impact['stamp_ns'] - pitch['stamp_ns']) <= time_bound_ns(rate_hz), \
            pitch['name']
        # the truth's spot is where the axis came closest (an end cap's centre for an end-cap
        # hit); the record's distance of an end hit is the contact point's own
        length = impact['distance_from_knob_m'] + impact['distance_from_tip_m']
        assert abs((1.0 - impact['bat_fraction']) * length - pitch['distance_from_tip_m']) \
            <= SPOT_BOUND_M
        assert impact['sweet_spot_speed_mps'] == pytest.approx(
            pitch['sweet_spot_speed_mps'], rel=SPEED_BOUND)
        assert impact['feature'] == pitch['feature']
    assert used == set(range(len(impacts)))
    misses = [p for p in truth['pitches'] if not p['contact']]
    assert len(document['near_misses']) == len(misses)
