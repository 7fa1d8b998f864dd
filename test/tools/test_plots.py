"""``--plot``: one PNG per impact; matplotlib only when asked."""

from pathlib import Path
from typing import Callable, List, Tuple

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.tools.analyze import BagAnalysis
from baseball_collision.tools.plots import plot_names
from support.bundled import bag_path

RunCli = Callable[[List[str]], Tuple[int, str, str]]


def test_plots_are_pngs_one_per_impact(tmp_path: Path, run_cli: RunCli) -> None:
    """--plot writes one PNG per impact into a new directory."""
    plots = tmp_path / 'plots'
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), '--plot',
                               str(plots)])
    assert code == 0, stderr
    files = sorted(plots.iterdir())
    assert [f.name for f in files] == sorted(f'pitches_90hz_impact_{n}.png' for n in range(1, 9))
    for file in files:
        data = file.read_bytes()
        assert data.startswith(b'\x89PNG\r\n\x1a\n') and len(data) > 10_000


def test_plot_names_tell_bags_of_the_same_name_apart() -> None:
    """<bag>_impact_<n>.png; two bags of one name get their position as a prefix."""
    def analysis(path: str, impacts: int) -> BagAnalysis:
        result = BagAnalysis(path=Path(path), selection=None, config=DetectorConfig())
        result.impacts = [None] * impacts
        return result
    names = plot_names([analysis('a/run.mcap', 2), analysis('b/run.mcap', 1),
                        analysis('c/other', 1)])
    assert names == ['1_run_impact_1.png', '1_run_impact_2.png', '2_run_impact_1.png',
                     'other_impact_1.png']
