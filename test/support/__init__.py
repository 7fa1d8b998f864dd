"""Shared test scenes, harnesses and comparisons (imported by tests; never a test module)."""

import ast
import os
from pathlib import Path
import subprocess
import sys
from typing import List, Sequence

REPO_ROOT = Path(__file__).resolve().parents[2]
"""The repository root (``test/support/..``/..)."""

SIGNAL_AFTER_BAG = """
import os, signal
# (Ctrl-C as at a terminal: a shell without job control starts its background jobs with
# SIGINT ignored, and an interpreter started so leaves it ignored)
signal.signal(signal.SIGINT, signal.default_int_handler)
from baseball_collision.tools import many_bags
real = many_bags.analyze_bag
def analyze_then_signal(*args, **kwargs):
    result = real(*args, **kwargs)
    os.kill(os.getpid(), signal.{name})
    return result
many_bags.analyze_bag = analyze_then_signal
"""
"""Python source for a child ``analyze``: it sends itself signal ``{name}`` (``str.format``)
once its first bag is analysed, mid-run, before any output is committed."""


def examples(count: int) -> int:
    """Scale a property test's example count: `HYPOTHESIS_SCALE=20 make test` runs 20x more."""
    return max(1, int(count * float(os.environ.get('HYPOTHESIS_SCALE', '1'))))


def modules_loaded(code: str, modules: Sequence[str]) -> List[str]:
    """
    Run ``code`` in a fresh interpreter; return which of ``modules`` it left imported, sorted.

    :raises AssertionError: the code failed (its stderr is the message).
    """
    probe = (f'{code}\nimport sys\n'
             f'print(sorted(m for m in {list(modules)!r} if m in sys.modules))')
    done = subprocess.run([sys.executable, '-c', probe], capture_output=True, text=True,
                          cwd=REPO_ROOT, timeout=60)
    assert done.returncode == 0, done.stderr
    return ast.literal_eval(done.stdout)
