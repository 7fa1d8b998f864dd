"""ament_pep257 over the package, its tests and its tools (the standard ament_python lint test)."""

from ament_pep257.main import main
import pytest
from support import REPO_ROOT

LINTED = ['baseball_collision', 'test', 'benchmarks', 'launch', 'setup.py']


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257() -> None:
    """No pep257 docstring errors under the ament configuration."""
    paths = [str(REPO_ROOT / p) for p in LINTED if (REPO_ROOT / p).exists()]
    rc = main(argv=paths)
    assert rc == 0, 'Found code style errors / warnings'
