"""Tests for baseball_collision.tools.rates: a bag's impacts at lower rates against its own."""

import json
import math
from pathlib import Path
from typing import Any, List

from baseball_collision.bags import BagReader
from baseball_collision.bags.decode import chunk_rows, SampleChunk
from baseball_collision.errors import ToolError
from baseball_collision.tools.analyze import (
    AnalysisOptions, analyze_bag, decimated_chunks, decimated_samples)
from baseball_collision.tools.rates import match, rate_lines, RateCheck
from baseball_collision.tools.report import to_json
import numpy as np
import pytest

from ..support.bundled import bag_path
from ..support.schema import Validator


def _chunk(roles: List[int], first: int) -> SampleChunk:
    """Return a chunk of the roles given, stamped first, first + 1, ... (ns)."""
    n = len(roles)
    stamps = np.arange(first, first + n, dtype=np.int64)
    return SampleChunk(np.asarray(roles, np.int8), stamps, ['world'] * n, np.zeros((n, 7)),
                       stamps.copy())


def test_decimation_keeps_every_kth_sample_of_each_role_across_chunks() -> None:
    """Each role counted on its own, over chunk boundaries; samples and chunks agree."""
    chunks = [_chunk([0, 1, 0, 1, 0], 0), _chunk([1, 0, 1, 1, 0, 0], 5), _chunk([1], 11)]
    roles = [0, 1, 0, 1, 0, 1, 0, 1, 1, 0, 0, 1]  # stamps 0-11
    for every in (1, 2, 3):
        for phase in range(every):
            kept = [int(s) for c in decimated_chunks(iter(chunks), every, phase)
                    for s in c.stamps_ns]
            expected = []
            for role in (0, 1):
                mine = [stamp for stamp, r in enumerate(roles) if r == role]
                expected += mine[phase::every]
            assert kept == sorted(expected), (every, phase)
            rows = [s.stamp_ns for s in decimated_samples(
                (row for c in chunks for row in chunk_rows(c)), every, phase)]
            assert rows == kept


def test_options_refuse_bad_rates() -> None:
    """Refused: ``every`` under 1, a phase out of range, a factor under 2 (a ToolError)."""
    for bad in ({'every': 0}, {'every': 2, 'phase': 2}, {'phase': -1}, {'decimate': (1,)},
                {'decimate': (2.5,)}, {'every': True}):
        with pytest.raises(ToolError, match='AnalysisOptions'):
            AnalysisOptions(**bad)


class _Impact:
    """An impact's stamp (ns) and what a rate check reads of it."""

    def __init__(self, stamp_ns: int, knob_m: float = 0.6, speed: float = 30.0,
                 sigma: float = 0.0) -> None:
        self.stamp_ns, self.distance_from_knob_m, self.sweet_spot_speed_mps = \
            stamp_ns, knob_m, speed
        self.time_uncertainty_s = sigma * 1e-6
        self.distance_from_knob_uncertainty_m = sigma * 1e-3
        self.sweet_spot_speed_uncertainty_mps = sigma * 0.1


def test_impacts_are_matched_one_to_one_nearest_first_within_the_window() -> None:
    """The nearest pair first; one beyond the window, or a second near one, is extra."""
    recorded = [_Impact(1_000_000_000), _Impact(3_000_000_000)]
    lower = [_Impact(1_000_050_000), _Impact(1_000_010_000), _Impact(2_000_000_000)]
    pairs, extra = match(lower, recorded)
    assert [(a.stamp_ns, b.stamp_ns) for a, b in pairs] == [(1_000_010_000, 1_000_000_000)]
    assert extra == 2


def test_matching_equals_the_brute_force_pairing() -> None:
    """Nearest pairs first, one to one: the same pairs as trying every pair (random stamps)."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        recorded = [_Impact(int(t)) for t in rng.integers(0, 400_000_000, 40)]
        lower = [_Impact(int(t)) for t in rng.integers(0, 400_000_000, 35)]
        window = int(rng.integers(1, 30_000_000))
        candidates = sorted((abs(a.stamp_ns - b.stamp_ns), i, j) for i, a in enumerate(lower)
                            for j, b in enumerate(recorded)
                            if abs(a.stamp_ns - b.stamp_ns) <= window)
        taken_lower, taken_recorded, expected = set(), set(), set()
        for _, i, j in candidates:
            if i not in taken_lower and j not in taken_recorded:
                taken_lower.add(i)
                taken_recorded.add(j)
                expected.add((id(lower[i]), id(recorded[j])))
        pairs, extra = match(lower, recorded, window)
        assert {(id(a), id(b)) for a, b in pairs} == expected
        assert extra == len(lower) - len(expected)


def test_a_checks_moves_and_sigma_shares() -> None:
    """Moves signed (lower minus recorded), scored over both sigmas combined."""
    check = RateCheck(every=2, phases=2, impacts=1, compared=2)
    recorded = _Impact(1_000_000_000, sigma=3.0)
    check.add(_Impact(1_000_004_900, knob_m=0.603, speed=31.5, sigma=4.0), recorded)  # 0.98
    check.add(_Impact(999_992_000, knob_m=0.6, speed=30.0, sigma=4.0), recorded)  # 1.6
    summary = check.summary()
    assert summary['found'] == 2 and summary['time_s']['max'] == pytest.approx(8e-6)
    assert summary['time_s']['mean'] == pytest.approx(-1.55e-6)
    assert summary['within_1_sigma']['time_s'] == 0.5
    assert summary['within_2_sigma']['time_s'] == 1.0
    assert summary['distance_from_knob_m']['max'] == pytest.approx(0.003)
    assert summary['sweet_spot_speed']['max'] == pytest.approx(0.05)
    assert summary['within_1_sigma']['sweet_spot_speed'] == 0.5  # 1.5 / 0.5 m/s = 3 sigma
    assert RateCheck(every=3, phases=3, impacts=0).summary()['time_s'] is None


def test_a_bag_at_a_quarter_of_its_rate_moves_as_its_truth_says() -> None:
    """
    ``pitches_360hz.mcap`` at 90 Hz, each of 4 phases: every impact found again, none more.

    Checked against the truth file (not used by the check): each impact's move from the
    recorded rate's equals its own error against the truth less the recorded rate's error
    (both from the truth), to a nanosecond's rounding; and the report and JSON carry it.
    """
    bag = bag_path('pitches_360hz.mcap')
    analysis = analyze_bag(bag, AnalysisOptions(decimate=(4,)), progress=False)
    [check] = analysis.rates
    assert (check.every, check.phases, check.impacts) == (4, 4, 8)
    assert (check.compared, check.found, check.extra) == (32, 32, 0)
    truth = {p['stamp_ns'] for p in json.loads(
        bag.with_name('pitches_360hz.truth.json').read_text())['pitches'] if p['contact']}

    def nearest(stamp: int) -> int:
        return min(truth, key=lambda t: abs(t - stamp))

    moves: List[float] = []
    for phase in range(4):
        lower = analyze_bag(bag, AnalysisOptions(every=4, phase=phase), progress=False,
                            use_truth=False)
        assert lower.messages in range(3480 // 4 - 2, 3480 // 4 + 3)
        for impact in lower.impacts:
            recorded = min(analysis.impacts, key=lambda i: abs(i.stamp_ns - impact.stamp_ns))
            assert nearest(impact.stamp_ns) == nearest(recorded.stamp_ns)
            moves.append((impact.stamp_ns - nearest(impact.stamp_ns))
                         - (recorded.stamp_ns - nearest(recorded.stamp_ns)))
    assert sorted(round(m) for m in moves) == sorted(round(m * 1e9) for m in check.time_s)
    assert 0.0 < max(abs(m) for m in check.time_s) < 5e-6  # at 90 Hz, exact samples
    lines = rate_lines(analysis.rates)
    assert lines[1].startswith('  every 4th frame: 32 of 32 impacts found again, 0 more;')
    document = to_json([analysis])
    entry = document['bags'][0]['rates'][0]
    assert entry['found'] == 32 and math.isclose(entry['time_s']['max'],
                                                 max(abs(m) for m in check.time_s))


def test_analyze_decimate_on_the_command_line(tmp_path: Path, run_cli: Any) -> None:
    """``--decimate 2 3``: a line per factor after the truth, and ``rates`` in the JSON."""
    out = tmp_path / 'a.json'
    code, stdout, stderr = run_cli(['analyze', str(bag_path('pitches_240hz_noisy.bag')),
                                    '--decimate', '2', '3', '2', '--json', str(out)])
    assert code == 0, stderr
    assert 'every 2nd frame: 16 of 16 impacts found again' in stdout
    assert 'every 3rd frame: 24 of 24' in stdout
    document = json.loads(out.read_text())
    assert Validator('analyze.schema.json').errors(document) == []
    rates = document['bags'][0]['rates']
    assert [r['every'] for r in rates] == [2, 3]
    assert all(0.0 <= r['within_2_sigma']['time_s'] <= 1.0 for r in rates)
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), '--decimate', '1'])
    assert code == 2 and 'must be >= 2' in stderr


def test_a_reader_and_a_decimated_analysis_count_the_same_samples() -> None:
    """Every 3rd sample of each role: a third of each role's messages, rounded up or down."""
    bag = bag_path('pitches_90hz.mcap')
    with BagReader(bag) as reader:
        counts: dict = {}
        for sample in reader.samples():
            counts[sample.role] = counts.get(sample.role, 0) + 1
    for phase in range(3):
        lower = analyze_bag(bag, AnalysisOptions(every=3, phase=phase), progress=False,
                            use_truth=False)
        assert lower.messages == sum(len(range(phase, n, 3)) for n in counts.values())
