"""Fixtures of the tools tests: the command line run in-process."""

from typing import Callable, List, Tuple

from baseball_collision.tools.cli import main
import pytest


@pytest.fixture
def run_cli(capsys: pytest.CaptureFixture) -> Callable[[List[str]], Tuple[int, str, str]]:
    """Return ``run(argv)``: ``main(argv)`` in-process; it returns (exit code, stdout, stderr)."""
    def run(argv: List[str]) -> Tuple[int, str, str]:
        try:
            code = main(argv)
        except SystemExit as exit_:  # argparse
            code = exit_.code
        captured = capsys.readouterr()
        return code, captured.out, captured.err
    return run
