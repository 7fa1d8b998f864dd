"""Tests for baseball_collision.core.toi's batch solver and the gap over time."""

import math

from baseball_collision.core.toi import distance, time_of_impact, time_of_impact_batch
from baseball_collision.core.toi.batch import CHUNK_ROWS
from baseball_collision.errors import CoreError
import numpy as np
import pytest
from support.scenes import agrees, reference_gap, vector_args, VECTORS


def test_vectors_batch() -> None:
    """The batch solver agrees with every shared vector in one call."""
    columns = list(zip(*[vector_args(c) for c in VECTORS]))
    got = time_of_impact_batch(*[np.array(column) for column in columns])
    assert got.shape == (len(VECTORS),) and got.dtype == np.float64
    wrong = [(c['family'], c['time_of_impact'], g) for c, g in zip(VECTORS, got)
             if not agrees(c['time_of_impact'], float(g), c['dt'])]
    assert wrong == []


def test_batch_returns_nan_for_bad_rows_only() -> None:
    """Non-finite rows, negative radii and dt <= 0 become NaN; good rows still solve."""
    n = 5
    ball0 = np.tile([2.0, 0.0, 0.0], (n, 1))
    ball1 = np.tile([0.0, 0.0, 0.0], (n, 1))
    tip = np.tile([1.0, 0.0, 0.0], (n, 1))
    knob = np.zeros((n, 3))
    ball0[1, 2] = math.nan
    ball1[2, 0] = math.inf
    bat_radius = np.array([0.05, 0.05, 0.05, -0.1, 0.05])
    dt = np.array([1.0, 1.0, 1.0, 1.0, 0.0])
    got = time_of_impact_batch(ball0, ball1, tip, tip, knob, knob, 0.05, bat_radius, dt)
    assert got[0] == pytest.approx(0.45)
    assert np.all(np.isnan(got[1:]))


def test_batch_shape_errors_raise() -> None:
    """Arrays that are not (N, 3), or radii of the wrong length, are refused."""
    with pytest.raises(CoreError, match='ball1'):
        time_of_impact_batch(np.zeros((2, 3)), np.zeros((3, 3)), np.zeros((2, 3)),
                             np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), 0.1, 0.1)
    with pytest.raises(CoreError, match='bat_radius'):
        time_of_impact_batch(*[np.zeros((2, 3))] * 6, 0.1, np.zeros(3))


@pytest.mark.parametrize('position', [0, 2, 3])
@pytest.mark.parametrize('value', ['abc', [[0.0, 0.0], [0.0]], [object()] * 3])
def test_batch_arguments_that_are_not_numbers_raise_core_error(position: int, value) -> None:
    """A string, a ragged list or objects for a point array or a radius: CoreError naming it."""
    arguments = [np.zeros((2, 3))] * 6 + [0.1, 0.1]
    arguments[position] = value
    name = ('ball0', 'ball1', 'tip0', 'tip1', 'knob0', 'knob1', 'ball_radius')[position]
    with pytest.raises(CoreError, match=f'{name} must be numbers'):
        time_of_impact_batch(*arguments)


def _agreement(points, ball_radius, bat_radius, dt) -> int:
    """Assert batch and scalar give the same time to the bit on every row; return contacts."""
    batch = time_of_impact_batch(*points, ball_radius, bat_radius, dt)
    n = len(batch)
    radii = np.broadcast_to(ball_radius, n)
    for i in range(n):
        result = time_of_impact(*[p[i] for p in points], radii[i], bat_radius, dt[i])
        if result is None:
            assert math.isnan(batch[i])
        else:
            assert batch[i] == result.time
    return int(np.count_nonzero(~np.isnan(batch)))


def test_batch_matches_scalar_on_random_intervals() -> None:
    """Batch and scalar agree row by row, to the bit, on 2000 random intervals."""
    rng = np.random.default_rng(7)
    n = 2000
    points = [rng.uniform(-0.6, 0.6, (n, 3)) for _ in range(6)]
    contacts = _agreement(points, rng.uniform(0.0, 0.1, n), 0.03, rng.uniform(0.002, 0.02, n))
    assert 200 < contacts < n - 200


def test_batch_on_every_core_matches_scalar_on_a_contact_heavy_set() -> None:
    """Enough rows for the threaded path (several chunks); most rows touch; every row agrees."""
    rng = np.random.default_rng(11)
    n = 3 * CHUNK_ROWS + 17
    knob0 = rng.uniform(-0.1, 0.1, (n, 3))
    tip0 = knob0 + rng.normal(0.0, 1.0, (n, 3)) * 0.3
    knob1, tip1 = knob0 + rng.normal(0.0, 0.01, (n, 3)), tip0 + rng.normal(0.0, 0.05, (n, 3))
    ball1 = knob0 + (tip0 - knob0) * rng.uniform(0.0, 1.0, (n, 1))
    ball0 = ball1 + rng.normal(0.0, 0.1, (n, 3))
    contacts = _agreement([ball0, ball1, tip0, tip1, knob0, knob1], 0.0366, 0.0331,
                          np.full(n, 1.0 / 360.0))
    assert contacts > 0.8 * n


def test_distance_matches_reference_gap() -> None:
    """The vectorised capsule gap equals the reference point-segment gap."""
    rng = np.random.default_rng(3)
    points = [rng.uniform(-1, 1, 3) for _ in range(6)]
    t = np.linspace(0.0, 0.01, 57)
    got = distance(t, *points, 0.04, 0.03, 0.01)
    expected = reference_gap(t / 0.01, *points, 0.07)
    assert got == pytest.approx(expected, abs=1e-12)


def test_batch_gives_the_same_rows_on_any_number_of_threads() -> None:
    """Chunks taken in turn by 1, 2 or 5 threads (more chunks than threads) fill every row."""
    rng = np.random.default_rng(12)
    n = 5 * CHUNK_ROWS + 3
    knob0 = rng.uniform(-0.1, 0.1, (n, 3))
    tip0 = knob0 + rng.normal(0.0, 0.3, (n, 3))
    ball0 = knob0 + (tip0 - knob0) * rng.uniform(0.0, 1.0, (n, 1)) + rng.normal(0.0, 0.1, (n, 3))
    points = [ball0, ball0 + rng.normal(0.0, 0.1, (n, 3)), tip0, tip0 + 0.01, knob0, knob0]
    one = time_of_impact_batch(*points, 0.0366, 0.0331, 1.0 / 360.0, threads=1)
    assert 0 < np.count_nonzero(~np.isnan(one)) < n
    for threads in (2, 5):
        got = time_of_impact_batch(*points, 0.0366, 0.0331, 1.0 / 360.0, threads=threads)
        assert np.array_equal(got.view(np.int64), one.view(np.int64))
