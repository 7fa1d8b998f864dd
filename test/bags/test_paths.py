"""What a bag path may be: files read by their first bytes; FIFOs, loops and devices refused."""

import os
from pathlib import Path
import shutil

from baseball_collision.bags import POINT_STAMPED, POSE_STAMPED, read_samples, select_topics
from baseball_collision.bags.common import file_format, open_bag
from baseball_collision.errors import BagError
import pytest
from support import REPO_ROOT

BAGS = REPO_ROOT / 'bags'


@pytest.mark.parametrize('source, name', [
    ('pitches_90hz.mcap', 'upper.MCAP'), ('pitches_90hz.mcap', 'misnamed.bag'),
    ('pitches_240hz_noisy.bag', 'ros1.BAG'), ('pitches_240hz_noisy.bag', 'ros1.mcap'),
    ('pitches_120hz_sqlite3/pitches_120hz_sqlite3.db3', 'lite.DB3')])
def test_a_bag_file_is_read_by_its_content(tmp_path: Path, source: str, name: str) -> None:
    """Upper-case suffixes and a suffix of another format read the same samples as the original."""
    copy = tmp_path / name
    shutil.copy(BAGS / source, copy)
    assert file_format(copy) == Path(source).suffix
    if source.endswith('.db3'):  # a bare .db3 has no metadata: compare with its directory
        source = 'pitches_120hz_sqlite3'
    assert list(read_samples(copy)) == list(read_samples(BAGS / source))
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no alias left behind


def test_a_fifo_is_refused_not_waited_on(tmp_path: Path) -> None:
    """A FIFO named x.mcap (which a reader would block on forever) is refused at once."""
    fifo = tmp_path / 'x.mcap'
    os.mkfifo(fifo)
    with pytest.raises(BagError, match='is a FIFO, not a regular file'):
        open_bag(fifo)
    directory = tmp_path / 'd'
    shutil.copytree(BAGS / 'pitches_120hz_sqlite3', directory)
    (directory / 'pitches_120hz_sqlite3.db3').unlink()
    os.mkfifo(directory / 'pitches_120hz_sqlite3.db3')
    with pytest.raises(BagError, match='is a FIFO'):
        open_bag(directory)


def test_a_symlink_loop_is_named(tmp_path: Path) -> None:
    """A loop of symbolic links is a loop, not 'bag not found'; a missing file is not found."""
    os.symlink(tmp_path / 'b.mcap', tmp_path / 'a.mcap')
    os.symlink(tmp_path / 'a.mcap', tmp_path / 'b.mcap')
    with pytest.raises(BagError, match='a symbolic link loop'):
        open_bag(tmp_path / 'a.mcap')
    with pytest.raises(BagError, match='bag not found'):
        open_bag(tmp_path / 'c.mcap')


def test_two_thousand_candidates_make_a_short_error() -> None:
    """2000 ball topics: one bounded line (the first 20 and a count), not 15 kB."""
    topics = {f'/ball_{index:04d}': POINT_STAMPED for index in range(2000)}
    topics['/bat_pose'] = POSE_STAMPED
    with pytest.raises(BagError) as caught:
        select_topics(topics)
    message = str(caught.value)
    assert message.startswith('2000 ball topics: /ball_0000, ')
    assert '... and 1980 more; pass --ball-topic' in message
    assert len(message) < 600 and '\n' not in message
    with pytest.raises(BagError) as caught:
        select_topics(topics, ball='/missing')
    assert '... and 1981 more' in str(caught.value) and len(str(caught.value)) < 1200
