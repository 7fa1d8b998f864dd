"""Truth files and the one matching rule: the first impact in a pitch's span."""

import json
from pathlib import Path
import re
import shutil
from typing import Any, Callable, Dict, List, Tuple

from baseball_collision.core.detector import NearMiss, Prediction
from baseball_collision.errors import ToolError
from baseball_collision.tools.truth import (
    compare_truth, LEADS_S, load_truth, match_pitch, prediction_errors, PredictionIndex,
    silence_clearings, TRUTH_FORMAT, truth_path)
import pytest
from support import REPO_ROOT

RunCli = Callable[[List[str]], Tuple[int, str, str]]


def test_truth_file_names() -> None:
    """The truth file sits beside the bag, the bag suffix replaced."""
    assert truth_path('runs/a.mcap') == Path('runs/a.truth.json')
    assert truth_path('runs/a.db3') == Path('runs/a.truth.json')
    assert truth_path('a.bag') == Path('a.truth.json')
    assert truth_path('runs/session.v2') == Path('runs/session.v2.truth.json')


def test_a_bag_directory_named_dot_has_its_truth_beside_it(tmp_path: Path, run_cli: RunCli,
                                                           monkeypatch: pytest.MonkeyPatch
                                                           ) -> None:
    """``cd bag && analyze .`` (also ``--no-truth``, ``--plot``): no crash after the analysis."""
    bag = tmp_path / 'session'
    code, _, stderr = run_cli(['simulate', str(bag), '--count', '2', '--rate', '120'])
    assert code == 0, stderr
    monkeypatch.chdir(bag)
    assert truth_path('.') == tmp_path / 'session.truth.json'
    assert truth_path('..') == tmp_path.parent / f'{tmp_path.name}.truth.json'
    assert truth_path(Path('sub', '..')) == tmp_path / 'session.truth.json'
    with pytest.raises(ToolError, match='cannot be a bag'):
        truth_path('/')
    code, stdout, stderr = run_cli(['analyze', '.', '--no-progress', '--no-truth'])
    assert code == 0 and stderr == '' and 'truth (' not in stdout
    code, stdout, stderr = run_cli(['analyze', '.', '--no-progress', '--plot',
                                    str(tmp_path / 'plots')])
    assert code == 0 and stderr == '', stderr
    assert 'truth (session.truth.json): 2/2 contacts found' in stdout
    assert 'written for' not in stdout  # (the truth file names 'session', the bag's own)
    assert (tmp_path / 'plots' / 'session_summary.png').is_file()


class _Hit:

    def __init__(self, stamp_ns: int, from_tip: float = 0.1, speed: float = 30.0) -> None:
        self.stamp_ns = stamp_ns
        self.distance_from_tip_m = from_tip
        self.sweet_spot_speed_mps = speed


def _pitch(start: int, contact: bool, stamp: int = 0) -> Dict[str, Any]:
    return {'name': f'p{start}', 'kind': 'barrel' if contact else 'miss_over',
            'start_ns': start, 'end_ns': start + 1000, 'contact': contact,
            'stamp_ns': stamp if contact else None, 'distance_from_tip_m': 0.1 if contact
            else None, 'sweet_spot_speed_mps': 30.0 if contact else None}


def test_truth_comparison_matches_per_pitch() -> None:
    """The first impact in a pitch's span is the match; others and strays are false impacts."""
    truth = {'pitches': [_pitch(0, True, 500), _pitch(2000, True, 2500), _pitch(4000, False)]}
    impacts = [_Hit(510, 0.101, 30.3), _Hit(700), _Hit(3500), _Hit(9000)]
    misses = [NearMiss(4100, 0.05, (0.0, 0.0, 0.05), (0.0, 0.0, 0.0), 0.9, 0.08)]
    result = compare_truth(impacts, misses, truth, 'x.truth.json')
    assert result.contacts == 2 and len(result.matched) == 1
    assert [p['name'] for p in result.missed] == ['p2000']
    assert [i.stamp_ns for i in result.false_impacts] == [700, 3500, 9000]
    assert result.time_errors_ns == [10]
    assert result.spot_errors_m == [pytest.approx(0.001)]
    assert result.speed_errors == [pytest.approx(0.01)]
    assert (result.misses, result.near_misses_in_misses) == (1, 1)
    data = result.as_dict()
    assert data['max_abs_time_error_ns'] == 10 and data['missed'] == ['p2000']
    json.dumps(data, allow_nan=False)
    with pytest.raises(ToolError, match='malformed pitch'):
        compare_truth([], [], {'pitches': [{'contact': True}]}, 'x')


def test_the_first_impact_of_a_pitch_is_its_match() -> None:
    """The earliest impact in the span matches, even when a later one is nearer the truth."""
    truth = {'pitches': [_pitch(0, True, 600)]}
    impacts = [_Hit(650), _Hit(590), _Hit(1001)]
    result = compare_truth(impacts, [], truth, 't.truth.json')
    assert [impact.stamp_ns for _, impact in result.matched] == [590]
    assert [impact.stamp_ns for impact in result.false_impacts] == [650, 1001]
    assert match_pitch(True, impacts, (0, 1000)) == (1, [0, 1])
    assert match_pitch(True, impacts) == (1, [0, 1, 2])
    assert match_pitch(False, impacts, (0, 1000)) == (None, [0, 1])
    assert match_pitch(True, impacts, (2000, 3000)) == (None, [])


def test_truth_files_are_checked(tmp_path: Path) -> None:
    """A truth file must be JSON in the truth format; the error names the file."""
    good = tmp_path / 'a.truth.json'
    good.write_text(json.dumps({'format': TRUTH_FORMAT, 'pitches': []}))
    assert load_truth(good)['pitches'] == []
    for name, text, words in (('b', '{', 'not valid JSON'), ('c', '{"pitches": []}', 'is not a'),
                              ('d', None, 'cannot read truth file')):
        path = tmp_path / f'{name}.truth.json'
        if text is not None:
            path.write_text(text)
        with pytest.raises(ToolError, match=words):
            load_truth(path)


def predicted(made_at_ns: int, stamp_ns: int) -> Prediction:
    """Return a prediction of a contact at ``stamp_ns`` made at ``made_at_ns``."""
    return Prediction(stamp_ns=stamp_ns, made_at_ns=made_at_ns, lead_s=0.0,
                      point=(0.0, 0.0, 0.01), normal=(0.0, 0.0, 1.0), bat_fraction=0.9,
                      distance_from_tip_m=0.1, ball_position=(0.0, 0.0, 0.0),
                      ball_velocity=(0.0, 0.0, 0.0), planned=False)


def test_predictions_are_scored_by_the_one_in_force_at_each_lead() -> None:
    """
    Per lead: the last prediction made that far ahead, unless cleared since; else None.

    In force as the node publishes it: from the frame that made it to the next prediction or
    clearing, however many frames in between did not predict (a bat tracked faster than the
    ball, a prediction period).
    """
    contact = 1_000_000_000
    made = [predicted(contact - 150_000_000, contact + 2_000_000),
            predicted(contact - 30_000_000, contact - 1_000_000)]
    scores = prediction_errors(made, [contact - 60_000_000], contact, (0.0, 0.0, 0.0))
    assert list(scores) == list(LEADS_S)
    assert scores[0.2] is None  # nothing made that early
    assert scores[0.1] == (pytest.approx(2e-3), pytest.approx(0.01))
    assert scores[0.05] is None  # cleared at 60 ms
    assert scores[0.02] == (pytest.approx(-1e-3), pytest.approx(0.01))
    kept = prediction_errors(made[:1], [], contact, (0.0, 0.0, 0.0))
    assert kept[0.05] == kept[0.02] == (pytest.approx(2e-3), pytest.approx(0.01))
    index = PredictionIndex(made, [contact - 60_000_000, contact + 5_000_000])
    assert index.in_force(contact - 60_000_001) is made[0]
    assert index.in_force(contact - 60_000_000) is None
    assert index.in_force(contact - 30_000_000) is made[1]
    assert index.in_force(contact + 5_000_000) is None
    late = index.errors(contact, (0.0, 0.0, 0.0), window_ns=100_000_000)
    assert late[0.1] is None and late[0.02] is not None  # made 150 ms before: not its own


def test_a_ball_silent_past_its_flights_span_ends_the_prediction_in_force() -> None:
    """
    A ball gap longer than the flight span ends the prediction in force where the node's does.

    At the gap's start + the span, or the prediction's instant + max_gap if later, where that
    comes before the ball's next sample; a shorter gap (a tracker that paused and brings the
    contact), or none in force at the gap's start, ends nothing.
    """
    ms = 1_000_000
    made = [predicted(100 * ms, 300 * ms), predicted(700 * ms, 1_000 * ms)]
    index = PredictionIndex(made)
    gaps = [(50 * ms, 90 * ms), (250 * ms, 600 * ms), (720 * ms, 1_400 * ms),
            (1_450 * ms, 1_600 * ms)]
    assert silence_clearings(index, gaps, 0.05, 0.215) == [465 * ms, 1_050 * ms]
    assert silence_clearings(index, gaps, 0.05, 0.0) == [350 * ms, 1_050 * ms, 1_450 * ms]
    ended = PredictionIndex(made, silence_clearings(index, gaps, 0.05, 0.215))
    assert ended.in_force(464 * ms) is made[0] and ended.in_force(465 * ms) is None
    assert ended.in_force(1_049 * ms) is made[1] and ended.in_force(1_050 * ms) is None


def _damaged(text: str) -> str:
    """Return the 90 Hz bag's truth with ``text`` replacing its first pitch's contact stamp."""
    truth = (REPO_ROOT / 'bags' / 'pitches_90hz.truth.json').read_text()
    first = json.loads(truth)['pitches'][0]['stamp_ns']
    return truth.replace(f'"stamp_ns": {first}', text, 1)


DAMAGES = {
    'missing key': lambda: _damaged('"stamp": 1'),
    'zero speed': lambda: re.sub(r'"sweet_spot_speed_mps": [0-9.e+-]+',
                                 '"sweet_spot_speed_mps": 0', _damaged(
                                     '"stamp_ns": 1700000000248723328'), count=1),
    'infinity': lambda: _damaged('"stamp_ns": Infinity'),
    'deep nesting': lambda: _damaged('"stamp_ns": ' + '[' * 100_000 + ']' * 100_000),
    'not json': lambda: '{"format": ',
}


@pytest.mark.parametrize('damage', DAMAGES)
def test_a_damaged_truth_file_is_ignored_with_a_note(tmp_path: Path, run_cli: RunCli,
                                                     damage: str) -> None:
    """Missing keys, a 0 speed, Infinity, deep nesting: one note, and the analysis runs."""
    bag = tmp_path / 'p.mcap'
    shutil.copy(REPO_ROOT / 'bags' / 'pitches_90hz.mcap', bag)
    (tmp_path / 'p.truth.json').write_text(DAMAGES[damage]())
    out = tmp_path / 'p.json'
    code, stdout, stderr = run_cli(['analyze', str(bag), '--json', str(out)])
    assert code == 0 and stderr == ''
    notes = [line for line in stdout.splitlines() if line.startswith('note: ')
             and line.endswith('the truth file was ignored')]
    assert len(notes) == 1 and len(notes[0]) < 300, notes
    assert 'summary: 8 impacts' in stdout and 'truth (' not in stdout
    bag_entry = json.loads(out.read_text())['bags'][0]
    assert bag_entry['truth'] is None and bag_entry['notes'] == [notes[0][len('note: '):]]


class _Counted:
    """An event whose ``stamp_ns`` reads are counted (in ``reads``)."""

    reads = 0

    def __init__(self, stamp_ns: int) -> None:
        self._stamp_ns = stamp_ns
        self.distance_from_tip_m, self.sweet_spot_speed_mps = 0.1, 30.0

    @property
    def stamp_ns(self) -> int:
        _Counted.reads += 1
        return self._stamp_ns


def test_compare_truth_reads_each_stamp_a_bounded_number_of_times() -> None:
    """1000 pitches and 1000 impacts: about one read per impact and pitch, not a million."""
    pitches, impacts, misses = [], [], []
    for i in range(1000):
        start = 1_000_000_000 * i
        contact = i % 4 != 3
        pitches.append({'start_ns': start, 'end_ns': start + 400_000_000, 'contact': contact,
                        'stamp_ns': start + 250_000_000, 'distance_from_tip_m': 0.1,
                        'sweet_spot_speed_mps': 30.0})
        (impacts if contact else misses).append(_Counted(start + 250_000_100))
    impacts.append(_Counted(600_000_000))  # between two pitches: a false impact
    _Counted.reads = 0
    result = compare_truth(impacts[::-1], misses, {'pitches': pitches}, 't.json')
    assert len(result.matched) == 750 and result.near_misses_in_misses == 250
    assert [impact.stamp_ns for impact in result.false_impacts] == [600_000_000]
    assert _Counted.reads < 10 * (len(impacts) + len(misses) + len(pitches))
