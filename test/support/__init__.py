"""Shared test scenes, harnesses and comparisons (imported by tests; never a test module)."""

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
"""The repository root (``test/support/..``/..)."""


def examples(count: int) -> int:
    """Scale a property test's example count: `HYPOTHESIS_SCALE=20 make test` runs 20x more."""
    return max(1, int(count * float(os.environ.get('HYPOTHESIS_SCALE', '1'))))
