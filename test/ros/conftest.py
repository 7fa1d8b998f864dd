"""Fixtures of the in-process node tests: harnesses on a context with discovery off, the hit."""

from typing import Any, Callable, Dict, Iterator, List, Optional

import pytest
from support.harness import Harness
from support.scenes import BASE_NS, first_contact, pitch


@pytest.fixture
def harness(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[..., Harness]]:
    """Make harnesses on a context with discovery off; tear them all down after the test."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    made: List[Harness] = []

    def make(overrides: Optional[Dict[str, Any]] = None,
             args: Optional[List[str]] = None) -> Harness:
        made.append(Harness(overrides, args))
        return made[-1]
    yield make
    for each in made:
        each.close()


@pytest.fixture(scope='module')
def truth_ns() -> int:
    """Return the exact first contact of the hitting pitch as an absolute stamp (ns)."""
    t = first_contact(pitch())
    assert t is not None
    return BASE_NS + int(round(t * 1e9))
