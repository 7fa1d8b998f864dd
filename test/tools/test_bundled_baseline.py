"""The package says today what it said when the baseline was recorded, on every bundled bag."""

import json

from support.baseline import analyze_documents, BASELINE
from support.documents import differences


def test_every_bundled_bag_and_model_unchanged() -> None:
    """Impacts, near misses, predictions, drops, gaps: stamps to the ns, floats to ULPs."""
    expected = json.loads(BASELINE.read_text())
    actual = json.loads(json.dumps(analyze_documents()))
    found = differences(actual, expected)
    assert found == [], '\n'.join(found[:20])
    assert sum(len(document['impacts']) for document in expected.values()) > 50


def test_a_smallest_gaps_place_may_move_by_its_last_bits_only() -> None:
    """Where a truth's smallest gap was (a flat minimum) within 1e-7; the gap itself to ULPs."""
    expected = {'pitches': [{'min_gap_m': -0.01652736453920623, 'min_gap_time_s': 0.25,
                             'min_gap_vector': [-0.0112633, -0.0013765018493085814, 0.0120165]}]}
    moved = json.loads(json.dumps(expected))
    moved['pitches'][0]['min_gap_vector'][1] = -0.0013765007432473078  # (an AMD EPYC's)
    moved['pitches'][0]['min_gap_time_s'] += 3e-10
    assert differences(moved, expected) == []
    moved['pitches'][0]['min_gap_vector'][1] += 1e-6
    moved['pitches'][0]['min_gap_m'] += 1.1e-9
    assert [line.split(':')[0] for line in differences(moved, expected)] == [
        '.pitches[0].min_gap_m', '.pitches[0].min_gap_vector[1]']


def test_a_near_miss_stamp_as_text_may_move_as_its_stamp_does() -> None:
    """A near miss's ``stamp_utc`` (its stamp as text) moves as its ``stamp_ns`` may; no other."""
    expected = {'near_misses': [{'stamp_ns': 1700000020251031851,
                                 'stamp_utc': '2023-11-14T22:13:40.251031851Z'}],
                'impacts': [{'stamp_utc': '2023-11-14T22:13:40.251031851Z'}]}
    moved = json.loads(json.dumps(expected))
    moved['near_misses'][0]['stamp_ns'] += 1  # (an AMD EPYC's, measured)
    moved['near_misses'][0]['stamp_utc'] = '2023-11-14T22:13:40.251031852Z'
    assert differences(moved, expected) == []
    moved['near_misses'][0]['stamp_utc'] = '2023-11-14T22:13:41.251031852Z'
    moved['impacts'][0]['stamp_utc'] = '2023-11-14T22:13:40.251031852Z'
    assert [line.split(':')[0] for line in differences(moved, expected)] == [
        '.impacts[0].stamp_utc', '.near_misses[0].stamp_utc']
