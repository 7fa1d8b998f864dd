"""Tests for baseball_collision.tools.sim sampling: stamps, jitter, noise, the truth as JSON."""

import json

from baseball_collision.core.bat import PoseBatGeometry
from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import sample, truth_dict
import numpy as np
import pytest

START_NS = 1_700_000_000_123_456_789


def test_truth_dict_is_json(scenarios: dict) -> None:
    """truth_dict round-trips through JSON with absolute stamps."""
    hit, miss = scenarios['barrel'][0], scenarios['miss_over'][0]
    record = json.loads(json.dumps(truth_dict(hit, START_NS)))
    assert record['stamp_ns'] == START_NS + round(hit.truth.time_s * 1e9)
    assert record['contact'] and record['kind'] == 'barrel'
    assert record['point'] == list(hit.truth.point)
    record = json.loads(json.dumps(truth_dict(miss, START_NS)))
    assert not record['contact'] and record['stamp_ns'] is None
    assert record['min_gap_stamp_ns'] == START_NS + round(miss.truth.min_gap_time_s * 1e9)


@pytest.mark.parametrize('rate', [90.0, 120.0, 240.0, 360.0])
def test_samples_are_the_truth_at_the_stamps(scenarios: dict, rate: float) -> None:
    """Without noise, every sample is the truth at its stamp; stamps are int64, increasing."""
    scenario = scenarios['barrel'][1]
    samples = sample(scenario, rate, np.random.default_rng(0), start_ns=START_NS)
    stamps = samples.ball_stamps_ns
    assert stamps.dtype == np.int64 and samples.bat_stamps_ns.dtype == np.int64
    assert np.all(np.diff(stamps) > 0) and stamps[0] == START_NS
    assert np.array_equal(stamps, samples.bat_stamps_ns)
    assert len(stamps) == int(scenario.t_end * rate) + 1
    assert np.all(np.abs(np.diff(stamps) - 1e9 / rate) <= 1.0)
    t = (stamps - START_NS) * 1e-9
    assert np.array_equal(samples.ball_positions, scenario.pitch.position(t))
    knobs, tips = scenario.swing.knob_tip(t)
    assert np.array_equal(samples.knobs, knobs) and np.array_equal(samples.tips, tips)
    for position, quaternion, knob, tip in zip(samples.bat_positions, samples.bat_quaternions,
                                               samples.knobs, samples.tips):
        got_knob, got_tip = scenario.swing.geometry.knob_and_tip(position, quaternion)
        assert np.abs(got_knob - knob).max() < 1e-12 and np.abs(got_tip - tip).max() < 1e-12


def test_360_hz_on_a_millisecond_grid_steps_2_and_3_ms(scenarios: dict) -> None:
    """grid_s=0.001 at 360 Hz stamps on whole milliseconds, in steps of 2 and 3 ms."""
    scenario = scenarios['end_cap'][0]
    samples = sample(scenario, 360.0, np.random.default_rng(0), grid_s=0.001,
                     start_ns=START_NS)
    steps = np.diff(samples.ball_stamps_ns)
    assert set(steps.tolist()) == {2_000_000, 3_000_000}
    assert np.all((samples.ball_stamps_ns - START_NS) % 1_000_000 == 0)
    t = (samples.ball_stamps_ns - START_NS) * 1e-9
    assert np.array_equal(samples.ball_positions, scenario.pitch.position(t))


def test_jitter_noise_and_bat_offset(scenarios: dict) -> None:
    """Jittered stamps still increase; noise is one draw per sample; the bat can be offset."""
    scenario = scenarios['handle'][0]
    samples = sample(scenario, 240.0, np.random.default_rng(5), jitter_s=3e-4, noise_m=0.002,
                     start_ns=START_NS, bat_offset_s=0.0013)
    for stamps in (samples.ball_stamps_ns, samples.bat_stamps_ns):
        assert stamps.dtype == np.int64 and np.all(np.diff(stamps) > 0)
        assert START_NS <= stamps[0] and stamps[-1] <= START_NS + round(scenario.t_end * 1e9)
    assert not np.array_equal(samples.ball_stamps_ns, samples.bat_stamps_ns)
    t_ball = (samples.ball_stamps_ns - START_NS) * 1e-9
    error = samples.ball_positions - scenario.pitch.position(t_ball)
    assert 0.0015 < error.std() < 0.0025
    t_bat = (samples.bat_stamps_ns - START_NS) * 1e-9
    knobs, tips = scenario.swing.knob_tip(t_bat)
    shake = samples.knobs - knobs
    assert np.allclose(samples.tips - tips, shake, atol=1e-12)  # the same draw: still rigid
    assert 0.0015 < shake.std() < 0.0025
    for position, quaternion, knob in zip(samples.bat_positions, samples.bat_quaternions,
                                          samples.knobs):
        got_knob, _ = scenario.swing.geometry.knob_and_tip(position, quaternion)
        assert np.abs(got_knob - knob).max() < 1e-12


def test_the_ball_at_its_own_rate(scenarios: dict) -> None:
    """``ball_rate_hz``: the ball's stamps at that rate, the bat's at ``rate_hz``, both true."""
    scenario = scenarios['barrel'][0]
    samples = sample(scenario, 1000.0, np.random.default_rng(2), grid_s=1e-3,
                     start_ns=START_NS, ball_rate_hz=60.0)
    ball_steps = np.diff(samples.ball_stamps_ns) * 1e-9
    bat_steps = np.diff(samples.bat_stamps_ns) * 1e-9
    assert np.all((ball_steps >= 0.016) & (ball_steps <= 0.017))
    assert np.all(bat_steps == 0.001)
    t_ball = (samples.ball_stamps_ns - START_NS) * 1e-9
    assert np.array_equal(samples.ball_positions, scenario.pitch.position(t_ball))
    knobs, _ = scenario.swing.knob_tip((samples.bat_stamps_ns - START_NS) * 1e-9)
    assert np.array_equal(samples.knobs, knobs)
    same = sample(scenario, 90.0, np.random.default_rng(2), jitter_s=2e-4, ball_rate_hz=90.0)
    assert np.array_equal(same.ball_stamps_ns, same.bat_stamps_ns)


@pytest.mark.parametrize('spread', [None, 0.3])
def test_noise_on_one_body(scenarios: dict, spread) -> None:
    """``noise_on`` keeps one body exact and gives the other the noise it has with 'both'."""
    scenario = scenarios['barrel'][0]
    drawn = {on: sample(scenario, 120.0, np.random.default_rng(3), jitter_s=2e-4, grid_s=1e-3,
                        noise_m=0.001, marker_spread_m=spread, noise_on=on)
             for on in ('both', 'ball', 'bat')}
    exact = sample(scenario, 120.0, np.random.default_rng(3), jitter_s=2e-4, grid_s=1e-3)
    both, ball, bat = drawn['both'], drawn['ball'], drawn['bat']
    for samples in (ball, bat):
        assert np.array_equal(samples.ball_stamps_ns, both.ball_stamps_ns)
    assert np.array_equal(ball.ball_positions, both.ball_positions)
    assert np.array_equal(bat.ball_positions, exact.ball_positions)
    for name in ('bat_positions', 'bat_quaternions', 'knobs', 'tips'):
        assert np.array_equal(getattr(bat, name), getattr(both, name))
        assert np.array_equal(getattr(ball, name), getattr(exact, name))
    assert not np.array_equal(both.knobs, exact.knobs)
    assert not np.array_equal(both.ball_positions, exact.ball_positions)


def test_sample_refuses_bad_input(scenarios: dict) -> None:
    """Non-positive rates (the bat's or the ball's), negative jitter or noise, an unknown body."""
    scenario = scenarios['barrel'][0]
    for kwargs in ({'rate_hz': 0.0}, {'rate_hz': 90.0, 'jitter_s': -1.0},
                   {'rate_hz': 90.0, 'noise_m': -1.0}, {'rate_hz': 90.0, 'grid_s': 0.0},
                   {'rate_hz': 90.0, 'noise_on': 'glove'},
                   {'rate_hz': 90.0, 'ball_rate_hz': -60.0}):
        with pytest.raises(ToolError):
            sample(scenario, rng=np.random.default_rng(0), **kwargs)


def test_a_bat_frame_turned_toward_a_point(scenarios: dict) -> None:
    """One frame's bat turns about its knob, pose and markers alike; the others stay."""
    samples = sample(scenarios['barrel'][0], 90.0, np.random.default_rng(0))
    j = len(samples.bat_stamps_ns) // 2
    knob, tip = samples.knobs[j], samples.tips[j]
    point = samples.ball_positions[j]
    turned = samples.with_bat_frame_turned(j, point, 0.15)
    assert np.linalg.norm(turned.tips[j] - tip) == pytest.approx(0.15)
    assert np.array_equal(turned.knobs[j], knob)
    assert np.linalg.norm(turned.tips[j] - knob) == pytest.approx(np.linalg.norm(tip - knob))
    across = point - knob - ((point - knob) @ (tip - knob)) * (tip - knob) / np.sum(
        (tip - knob) ** 2)
    assert (turned.tips[j] - tip) @ across > 0.0  # toward the point
    rotated = PoseBatGeometry().knob_and_tip(turned.bat_positions[j], turned.bat_quaternions[j])
    assert np.allclose(rotated, (turned.knobs[j], turned.tips[j]), atol=1e-9)
    others = np.arange(len(samples.bat_stamps_ns)) != j
    for name in ('bat_positions', 'bat_quaternions', 'knobs', 'tips'):
        assert np.array_equal(getattr(turned, name)[others], getattr(samples, name)[others])
    with pytest.raises(ToolError, match='no bat frame'):
        samples.with_bat_frame_turned(len(samples.bat_stamps_ns), point, 0.1)
    with pytest.raises(ToolError, match='axis'):
        samples.with_bat_frame_turned(j, tip + (tip - knob), 0.1)


def test_a_bat_frame_deleted(scenarios: dict) -> None:
    """``without_bat_frame``: the bat's frames but that one, pose and markers alike."""
    samples = sample(scenarios['barrel'][0], 90.0, np.random.default_rng(0))
    j = len(samples.bat_stamps_ns) // 2
    deleted = samples.without_bat_frame(j)
    assert len(deleted.bat_stamps_ns) == len(samples.bat_stamps_ns) - 1
    assert samples.bat_stamps_ns[j] not in deleted.bat_stamps_ns
    for name in ('bat_stamps_ns', 'bat_positions', 'bat_quaternions', 'knobs', 'tips'):
        assert np.array_equal(getattr(deleted, name), np.delete(getattr(samples, name), j, 0))
    assert np.array_equal(deleted.ball_positions, samples.ball_positions)
