"""The one parameter table: its entries, validate_parameters, and DetectorConfig built from it."""

from dataclasses import fields, replace
import math
from typing import Any, Dict

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import (
    DEFAULTS, Detector, DetectorConfig, Kind, PARAMETERS, Range, SPECS, validate_parameters)
from baseball_collision.errors import CoreError
import pytest

DETECTOR_FIELDS = {f.name for f in fields(DetectorConfig)} - {'profile', 'geometry'}
BAT_DESCRIPTION = {'bat_profile', 'bat_length', 'bat_radius', 'bat_axis', 'knob_offset',
                   'tip_offset'}


def test_every_entry_is_whole() -> None:
    """Unique names, a known kind, a default in range, a doc; ranges only on numbers."""
    assert len(SPECS) == len(PARAMETERS)
    for spec in PARAMETERS:
        assert isinstance(spec.kind, Kind) and spec.doc, spec.name
        assert spec.check(spec.default) == spec.check(spec.check(spec.default)), spec.name
        if spec.bounds is not None:
            assert spec.kind in (Kind.DOUBLE, Kind.INTEGER), spec.name
            assert spec.bounds.low < spec.bounds.high, spec.name
        if spec.choices:
            assert spec.kind == Kind.STRING and spec.default in spec.choices, spec.name
        assert spec.kind != Kind.DOUBLE or spec.bounds is not None, spec.name  # no NaN or inf
    with pytest.raises(ValueError):
        Kind('float')


def test_detector_config_takes_its_defaults_from_the_table() -> None:
    """
    Every DetectorConfig field but profile and geometry is a parameter, default and all.

    But for prediction: the table's (the node's) predicts 0.3 s ahead every 10 ms; a config
    made in code predicts only when given a horizon, and then every frame.
    """
    assert DETECTOR_FIELDS <= set(SPECS)
    config = DetectorConfig()
    off = {'prediction_horizon': 0.0, 'prediction_period': 0.0}
    for name in DETECTOR_FIELDS:
        expected = off.get(name, DEFAULTS[name])
        assert getattr(config, name) == (tuple(expected) if name == 'up_axis' else expected)
    assert (DEFAULTS['prediction_horizon'], DEFAULTS['prediction_period']) == (0.3, 0.01)
    assert DetectorConfig.from_parameters({}) == replace(
        config, prediction_horizon=0.3, prediction_period=0.01)
    assert DetectorConfig.from_parameters(off) == config
    assert config.profile == WOOD_BAT_34
    assert config.geometry.tip_offset == (0.0, 0.0, DEFAULTS['tip_offset'])


def _changed(spec: Any) -> Any:
    """Return another valid value of a parameter."""
    if spec.choices:
        return next(choice for choice in spec.choices if choice != spec.default)
    if spec.kind == Kind.BOOL:
        return not spec.default
    if spec.kind == Kind.STRING:
        return spec.default + 'x'
    if spec.kind == Kind.DOUBLE_ARRAY:
        return [0.0, 1.0, 0.0] if spec.name == 'up_axis' else [0.0, 0.02, 0.8, 0.03]
    low, high = spec.bounds.low, spec.bounds.high
    return type(spec.default)((low + high) / 2) if spec.default != (low + high) / 2 \
        else type(spec.default)(high)


def test_runtime_parameters_never_touch_what_needs_a_restart() -> None:
    """Changing any parameter not read-only leaves Detector.RESTART_FIELDS as they are."""
    base = DetectorConfig.from_parameters({})
    runtime = [spec for spec in PARAMETERS if not spec.read_only]
    assert {'ball_radius', 'max_gap', 'near_miss_threshold', 'stale_timeout'} <= {
        spec.name for spec in runtime}
    for spec in runtime:
        config = DetectorConfig.from_parameters({spec.name: _changed(spec)})
        for name in Detector.RESTART_FIELDS:
            assert getattr(config, name) == getattr(base, name), (spec.name, name)
    for name in BAT_DESCRIPTION | {'model', 'bat_input', 'frame_id'}:
        assert SPECS[name].read_only, name


def test_validate_fills_converts_and_ignores_unknown_names() -> None:
    """Missing: default; an int for a double: float; arrays: lists of floats; others ignored."""
    checked = validate_parameters({'max_gap': 1, 'up_axis': (0, 2, 0), 'use_sim_time': True,
                                   'bat_profile': None})
    assert set(checked) == set(SPECS)
    assert checked['max_gap'] == 1.0 and isinstance(checked['max_gap'], float)
    assert checked['up_axis'] == [0.0, 2.0, 0.0] and checked['bat_profile'] == []
    assert checked['qos_depth'] == 100 and checked['model'] == 'c2'
    config = DetectorConfig.from_parameters(checked)
    assert config.max_gap == 1.0 and config.up_axis == (0.0, 1.0, 0.0)


@pytest.mark.parametrize('values, words', [
    ({'ball_radius': True}, ["'ball_radius'", 'must be a number', 'type bool']),
    ({'ball_radius': 0.0}, ["'ball_radius' = 0.0", 'out of range (0.0, 0.5]']),
    ({'max_gap': 0.0}, ["'max_gap' = 0.0", 'out of range (0.0, 10.0]']),
    ({'max_gap': 10.5}, ["'max_gap' = 10.5", 'out of range']),
    ({'max_chord_error': math.nan}, ["'max_chord_error' = nan", 'out of range']),
    ({'velocity_degree': 5.0}, ["'velocity_degree'", 'must be an integer', 'type double']),
    ({'velocity_degree': 7}, ["'velocity_degree' = 7", 'out of range [1, 6]']),
    ({'qos_depth': 0}, ["'qos_depth' = 0", 'out of range [1, 10000]']),
    ({'publish_markers': 1}, ["'publish_markers'", 'must be a boolean', 'type integer']),
    ({'frame_id': 3}, ["'frame_id'", 'must be a string']),
    ({'model': 'cubic'}, ["'model' must be one of linear, rigid, spline, c2, got 'cubic'"]),
    ({'qos': 'best_effort'}, ["'qos' must be one of sensor_data, reliable"]),
    ({'up_axis': [0.0, 0.0, 0.0]}, ["'up_axis' must be a non-zero 3-vector"]),
    ({'up_axis': [1.0, 0.0]}, ["'up_axis' must be a non-zero 3-vector"]),
    ({'up_axis': ['up', 0, 0]}, ["'up_axis' must be a list of numbers"]),
    ({'bat_profile': [0.1, 0.02, 0.3]}, ["'bat_profile'", 'pairs']),
    ({'bat_profile': [0.1]}, ["'bat_profile'", 'pairs']),  # (no flat[-2]: an IndexError)
    ({'bat_profile': [0.5, 0.02, 0.1, 0.03]}, ["'bat_profile'", 'increase']),
    ({'bat_axis': 'w'}, ["'bat_axis' must be one of x, y, z, -x, -y, -z"]),
    ({'knob_offset': 0.5, 'tip_offset': 0.5}, ["'knob_offset'", "'tip_offset'", '1 mm']),
    ({'ball_topic': 'bat_pose'}, ["'ball_topic'", "'bat_pose_topic'", 'different topics']),
    ({'bat_input': 'points', 'knob_topic': 't', 'tip_topic': 't'}, ["'tip_topic'"]),
])
def test_bad_values_are_refused_in_one_line_naming_the_parameter(values: Dict[str, Any],
                                                                 words: list) -> None:
    """Type, range (open bounds too), choices and the cross-field checks: one-line CoreError."""
    with pytest.raises(CoreError) as caught:
        validate_parameters(values)
    message = str(caught.value)
    assert '\n' not in message
    for word in words:
        assert word in message
    with pytest.raises(CoreError) as again:
        DetectorConfig.from_parameters(values)
    assert str(again.value) == message


def test_points_input_checks_its_own_topics() -> None:
    """With bat_input points the pose topic may equal the ball's (it is not subscribed)."""
    validate_parameters({'bat_input': 'points', 'bat_pose_topic': 'ball'})
    with pytest.raises(CoreError, match='different topics'):
        validate_parameters({'bat_input': 'points', 'knob_topic': 'ball'})


def test_detector_config_checks_fields_like_the_node() -> None:
    """Direct construction refuses what the node refuses (a bool is no radius) and converts."""
    with pytest.raises(CoreError, match="'ball_radius'"):
        DetectorConfig(ball_radius=True)
    with pytest.raises(CoreError, match="'velocity_degree'"):
        DetectorConfig(velocity_degree=True)
    assert DetectorConfig(max_gap=1).max_gap == 1.0


def test_range_notation_and_membership() -> None:
    """Open bounds are refused, closed ones taken; NaN never is in a range."""
    half_open = Range(0.0, 1.0, low_open=True)
    assert str(half_open) == '(0.0, 1.0]' and str(Range(1, 6)) == '[1, 6]'
    assert 0.0 not in half_open and 1.0 in half_open and 0.5 in half_open
    assert math.nan not in half_open and 1.0 not in Range(0.0, 1.0, high_open=True)


def test_a_variant_is_the_configuration_replaced_and_checked_once() -> None:
    """``variant`` is ``dataclasses.replace``'s configuration, kept; a bad change is refused."""
    config = DetectorConfig(model='c2', bat_input='pose', look_ahead=2, tracker_noise=-1.0)
    variant = config.variant(look_ahead=0, model='spline')
    assert variant == replace(config, look_ahead=0, model='spline') and variant != config
    assert config.variant(model='spline', look_ahead=0) is variant  # (kept, any order)
    assert DetectorConfig(model='c2', bat_input='pose', look_ahead=2,
                          tracker_noise=-1.0).variant(look_ahead=0, model='spline') is variant
    with pytest.raises(CoreError, match='look_ahead'):
        config.variant(look_ahead=7)


def test_a_config_of_the_wrong_kind_is_refused_by_name() -> None:
    """A dict for a config, or no profile or geometry: a CoreError (an AttributeError later)."""
    for field_name, value in (('profile', None), ('profile', 0.03), ('geometry', (0.0, 0.8))):
        with pytest.raises(CoreError, match=f'^{field_name} must be a '):
            DetectorConfig(**{field_name: value})
    with pytest.raises(CoreError, match='config must be a DetectorConfig, not dict'):
        Detector({'model': 'c2'})
    detector = Detector()
    with pytest.raises(CoreError, match='config must be a DetectorConfig, not dict'):
        detector.reconfigure({'near_miss_threshold': 0.2})


@pytest.mark.parametrize('given', [[('model', 'linear')], 'model', None, 5])
def test_parameters_not_a_mapping_are_an_error(given: object) -> None:
    """
    A list of (name, value) pairs, a str, None: a CoreError, never every default unawares.

    ``DetectorConfig.from_parameters([('model', 'linear')])`` gave the default ``c2`` config
    (no name was ``in`` the list), and a str raised TypeError from inside.
    """
    for build in (DetectorConfig.from_parameters, validate_parameters):
        with pytest.raises(CoreError, match='parameters must be a mapping of names to values'):
            build(given)
