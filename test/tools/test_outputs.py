"""All-or-nothing outputs: staged beside their targets, placed at commit, never overwriting."""

from pathlib import Path

from baseball_collision.errors import ToolError
from baseball_collision.tools.outputs import Outputs
import pytest


def test_outputs_are_all_or_nothing(tmp_path: Path) -> None:
    """Nothing appears before commit; an exception removes every temporary."""
    targets = {'json': tmp_path / 'a.json', 'plot': tmp_path / 'plots',
               'out_bag': tmp_path / 'o.mcap'}
    with pytest.raises(RuntimeError):
        with Outputs(**targets) as outputs:
            outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
            outputs.stage_text('json', '{}')
            outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
            raise RuntimeError('boom')
    assert list(tmp_path.iterdir()) == []
    with Outputs(**targets) as outputs:
        outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
        outputs.stage_text('json', '{}')
        outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
        assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith('.')) == []
        outputs.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.json', 'o.mcap', 'plots']
    assert (tmp_path / 'plots' / 'a.png').read_bytes() == b'x'
    with pytest.raises(ToolError, match='exists already'):
        Outputs(json=tmp_path / 'a.json')
    with pytest.raises(ToolError, match='does not exist'):
        Outputs(csv=tmp_path / 'nowhere' / 'a.csv')


def test_a_target_that_appears_before_the_commit_is_kept(tmp_path: Path) -> None:
    """Commit refuses a target made meanwhile, leaves it as it was, and no temporary behind."""
    with pytest.raises(ToolError, match='exists already'):
        with Outputs(json=tmp_path / 'a.json', csv=tmp_path / 'b.csv') as outputs:
            outputs.stage_text('json', '{"a": 1}\n')
            outputs.stage_text('csv', 'a\n')
            (tmp_path / 'b.csv').write_text('mine')
            outputs.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.json', 'b.csv']
    assert (tmp_path / 'a.json').read_text() == '{"a": 1}\n'
    assert (tmp_path / 'b.csv').read_text() == 'mine'


def test_outputs_get_the_usual_permissions(tmp_path: Path) -> None:
    """A staged file or directory ends up with the mode of one made directly (umask applied)."""
    (tmp_path / 'plain.txt').write_text('x')
    (tmp_path / 'plain').mkdir()
    with Outputs(text=tmp_path / 'a.txt', plot=tmp_path / 'plots') as outputs:
        outputs.stage_text('text', 'x')
        outputs.stage_directory('plot', lambda directory: None)
        outputs.commit()
    assert (tmp_path / 'a.txt').stat().st_mode == (tmp_path / 'plain.txt').stat().st_mode
    assert (tmp_path / 'plots').stat().st_mode == (tmp_path / 'plain').stat().st_mode
