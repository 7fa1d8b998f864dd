"""ament_flake8 over the package, its tests and its tools (the standard ament_python lint test)."""

from ament_flake8.main import main_with_errors
import pytest
from support import REPO_ROOT

LINTED = ['baseball_collision', 'test', 'benchmarks', 'launch', 'setup.py']


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8() -> None:
    """No flake8 errors under the ament configuration (with the buildfarm's plugins)."""
    paths = [str(REPO_ROOT / p) for p in LINTED if (REPO_ROOT / p).exists()]
    rc, errors = main_with_errors(argv=paths)
    assert rc == 0, 'Found %d code style errors / warnings:\n' % len(errors) + '\n'.join(errors)
