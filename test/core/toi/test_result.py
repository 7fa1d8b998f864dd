"""Tests for baseball_collision.core.toi.result: the feature names are plain strings too."""

import json

from baseball_collision.core.toi import Feature, time_of_impact


def test_features_are_strings_everywhere() -> None:
    """A Feature compares, hashes, formats and serialises as its value."""
    assert [str(f) for f in Feature] == ['side', 'knob_end', 'tip_end']
    assert Feature.TIP_END == 'tip_end' and f'{Feature.KNOB_END}' == 'knob_end'
    assert {'side': 1}[Feature.SIDE] == 1
    assert json.dumps({Feature.SIDE: Feature.TIP_END}) == '{"side": "tip_end"}'


def test_the_solver_reports_a_feature_member() -> None:
    """The result's feature is a Feature (and equal to its string)."""
    result = time_of_impact([2.0, 0, 0], [0.0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0],
                            [0, 0, 0], 0.05, 0.05, 1.0)
    assert result.feature is Feature.TIP_END and result.feature == 'tip_end'
