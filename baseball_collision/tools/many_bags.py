"""
``analyze`` over many bags: a directory of bags stands for its bags, every core analyses them.

:func:`analyze_bags` runs :func:`~.analyze.analyze_bag` over bags ``jobs`` at a time (one
bag per task of :func:`~.pool.in_pool`), in input order; :func:`bag_paths` says which bags
the paths on the command line name.
"""

import os
from pathlib import Path
from typing import Any, Iterable, List, Optional, Tuple, TYPE_CHECKING, Union

from .analyze import AnalysisOptions, analyze_bag, BagAnalysis
from .pool import in_pool
from .truth import BAG_SUFFIXES
from ..core.toi.batch import cores
from ..errors import ToolError

if TYPE_CHECKING:  # the writer's modules are imported only when a bag is written
    from ..bags import BagWriter


def is_bag(path: Path) -> bool:
    """Return whether ``path`` is one bag: a ROS 2 bag directory or a bag file."""
    if path.is_dir():
        return (path / 'metadata.yaml').is_file()
    return path.suffix.lower() in BAG_SUFFIXES


def bag_paths(paths: Iterable[os.PathLike]) -> List[Path]:
    """
    Return the bags named by ``paths``, in order: a directory of bags stands for its bags.

    A ROS 2 bag directory (one with ``metadata.yaml``) is itself one bag; any other directory
    stands for the bags inside it and in its subdirectories (bag files and bag directories, by
    name at each level, a directory's bags before its subdirectories'; a season of days of
    bags); anything else is kept as given (``analyze_bag`` says what is wrong with it).

    :raises ToolError: a directory that is neither a bag nor holds one.
    """
    found: List[Path] = []
    for path in map(Path, paths):
        if path.is_dir() and not is_bag(path):
            inside = _bags_under(path)
            if not inside:
                raise ToolError(f'no bags in {path}: neither a ROS 2 bag directory (no '
                                'metadata.yaml) nor a directory holding .mcap, .db3 or .bag '
                                'files or bag directories')
            found.extend(inside)
        else:
            found.append(path)
    return found


def _bags_under(directory: Path) -> List[Path]:
    """Return the bags in a directory that is no bag, then in its subdirectories, by name."""
    entries = sorted(directory.iterdir())
    bags = [entry for entry in entries if is_bag(entry)]
    for entry in entries:
        if entry.is_dir() and not is_bag(entry):
            bags.extend(_bags_under(entry))
    return bags


Skipped = Tuple[Path, str]
"""A bag ``analyze_bags`` skipped (``skipped`` given): its path and why (one line)."""


def _analyze_one(path: Path, options: AnalysisOptions, use_truth: bool, read_ahead: int,
                 keep_going: bool, **more: Any) -> Union[BagAnalysis, Skipped]:
    """Analyse one bag; with ``keep_going`` a ``ToolError`` comes back as (path, why)."""
    try:
        return analyze_bag(path, options, use_truth=use_truth, read_ahead=read_ahead, **more)
    except ToolError as error:
        if not keep_going:
            raise
        return path, str(error)


def _analyze_in_worker(job: Tuple[Path, AnalysisOptions, bool, int, bool]
                       ) -> Union[BagAnalysis, Skipped]:
    """Analyse one bag in a pool process (no progress bar: the parent counts bags)."""
    return _analyze_one(*job, progress=False)


def worker_read_ahead(workers: int) -> int:
    """
    Return the chunks a pool worker reads ahead (``analyze_bag``'s ``read_ahead``).

    One while a core is spare; none with a worker on every core, where a reading thread would
    only take the other workers' time (reading ahead costs a bag's analysis 6-16 % more CPU,
    and gains wall time only on a spare core: BENCHMARKS.md, "Reading a bag ahead").
    """
    return 1 if workers < cores() else 0


def analyze_bags(paths: Iterable[os.PathLike], options: AnalysisOptions = AnalysisOptions(), *,
                 jobs: Optional[int] = None, out_bag: Optional['BagWriter'] = None,
                 progress: bool = True, use_truth: bool = True,
                 skipped: Optional[List[Skipped]] = None) -> List[BagAnalysis]:
    """
    Run :func:`analyze_bag` over bags, ``jobs`` at a time in a process pool; in input order.

    The bag-level entry point of ``analyze``: ``paths`` go through :func:`bag_paths`; one bag,
    or one job, runs in this process as :func:`analyze_bag` alone. Otherwise each bag is one
    task of a pool of ``jobs`` processes; the results come back in the order of the bags, and
    the first bag (in that order) that fails stops the pool and raises its error, as one bag
    after another would. A long run shows a bar of bags done on a terminal.

    :param jobs: processes (None: one per core this process may use).
    :param out_bag: an open writer for the output bag (one bag only).
    :param progress: show progress bars (per bag in one process; bags done in a pool).
    :param skipped: None: the first bag that fails stops the run; a list: a bag that cannot
        be analysed (a ``ToolError``: corrupt, truncated, not a bag, its topics missing) is
        appended to it as (path, why) and left out, and the others go on (``--keep-going``).
    :returns: one :class:`BagAnalysis` per bag analysed, in order.
    :raises ToolError: as :func:`analyze_bag`, for the first failing bag (``skipped`` None);
        ``out_bag`` with more than one bag; a directory without bags; ``jobs`` under 1 or not
        an int.
    """
    if jobs is not None and (jobs.__class__ is not int or jobs < 1):
        raise ToolError(f'jobs must be a whole number of processes, at least 1; got {jobs!r}')
    bags = bag_paths(paths)
    if out_bag is not None and len(bags) > 1:
        raise ToolError('--out-bag takes one BAG; run analyze once per bag')
    keep_going = skipped is not None
    workers = min(cores() if jobs is None else jobs, len(bags))
    if workers <= 1:
        return _analysed([_analyze_one(path, options, use_truth, 1, keep_going, out_bag=out_bag,
                                       progress=progress) for path in bags], skipped)
    tasks = [(path, options, use_truth, worker_read_ahead(workers), keep_going)
             for path in bags]
    return _analysed(in_pool(_analyze_in_worker, tasks, workers, progress=progress), skipped)


def _analysed(results: List[Union[BagAnalysis, Skipped]],
              skipped: Optional[List[Skipped]]) -> List[BagAnalysis]:
    """Return the analyses among ``results``; the bags skipped go to ``skipped``."""
    analyses = []
    for result in results:
        if isinstance(result, BagAnalysis):
            analyses.append(result)
        elif skipped is not None:
            skipped.append(result)
    return analyses
