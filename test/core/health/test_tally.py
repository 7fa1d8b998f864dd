"""What the node counts: messages lost from the stamps alone or from sequence numbers."""

from baseball_collision.core.health import Tally


def _gaps(stamps) -> int:
    tally = Tally(started=0.0)
    for stamp in stamps:
        tally.stamped('ball', stamp)
    return tally.lost()['ball']


def test_messages_lost_are_estimated_from_the_stamps() -> None:
    """A 1 kHz stream missing 5 and then 37 messages: 42 lost; steady stamps: none."""
    stamps = [1_000_000 * k for k in range(1, 200)]
    assert _gaps(stamps) == 0
    kept = [s for k, s in enumerate(stamps) if not 50 <= k < 55 and not 100 <= k < 137]
    assert _gaps(kept) == 42


def test_glitches_and_other_clocks_are_not_losses() -> None:
    """A lone stamp glitched 0.5 s ahead, a second publisher 3 s behind, a pause: no loss."""
    stamps = [3_000_000_000 + 1_000_000 * k for k in range(200)]
    glitched = stamps[:80] + [stamps[80] + 500_000_000] + stamps[80:]
    assert _gaps(glitched) == 0
    stale = [s for pair in zip(stamps, (s - 3_000_000_000 for s in stamps)) for s in pair]
    assert _gaps(stale) == 0
    paused = stamps[:100] + [s + 5_000_000_000 for s in stamps[100:]]
    assert _gaps(paused) == 0


def test_a_sample_whose_own_stamp_glitched_is_not_a_loss() -> None:
    """
    A lone glitch in place of its sample's stamp (the tracker misstamped sample 80): no loss.

    Its message arrived (the detector drops it as ``stamp_ahead``): the hole it leaves in the
    stamps is its own slot (found by the fault benchmark: one message "lost" per glitch).
    """
    stamps = [3_000_000_000 + 1_000_000 * k for k in range(200)]
    for ahead in (30_000_000, 500_000_000, 1_000_000_000):
        glitched = stamps[:80] + [stamps[80] + ahead] + stamps[81:]
        assert _gaps(glitched) == 0, ahead
    missing = stamps[:80] + [stamps[80] + 500_000_000] + stamps[86:]  # and 5 really lost
    assert _gaps(missing) == 5


def test_the_tally_prefers_sequence_numbers() -> None:
    """With numbers: exact across a pause; without: the stamps (a pause hides the loss)."""
    messages = [(1 + k, 10**12 + k * 1_000_000) for k in range(200)]
    messages = messages[:90] + [(n, t + 1_500_000_000) for n, t in messages[110:]]
    numbered, stamped = Tally(started=0.0), Tally(started=0.0)
    for sequence, stamp in messages:
        numbered.stamped('ball', stamp, sequence)
        stamped.stamped('ball', stamp)
    assert numbered.lost()['ball'] == 20 and stamped.lost()['ball'] == 0
