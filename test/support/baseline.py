"""
What ``analyze --json`` says about every bundled bag with every model: the behaviour record.

``python test/support/baseline.py --write`` records it into ``bundled_baseline.json`` beside
this file; ``test_bundled_baseline`` checks that the package still says the same, stamps to
the nanosecond and floats to ``documents.REL_TOL``. Re-record only for an intended change of
behaviour, and say so in the commit.
"""

import argparse
import json
import os
from pathlib import Path
import subprocess
import sys
import tempfile
from typing import Any, Dict, List

REPO_ROOT = Path(__file__).resolve().parents[2]
BASELINE = Path(__file__).with_name('bundled_baseline.json')
BAGS = ('pitches_90hz.mcap', 'pitches_120hz_sqlite3', 'pitches_240hz_noisy.bag',
        'pitches_360hz.mcap', 'pitches_180hz_rebound.mcap', 'pitches_1khz_arm.mcap')
MODELS = ('linear', 'rigid', 'spline', 'c2')
RUNS: Dict[str, List[str]] = {
    **{model: ['--model', model] for model in MODELS},
    'predict': ['--model', 'rigid', '--predict'],  # on the first bag only (see below)
}


def _canonical(value: Any) -> Any:
    """Drop wall times; round floats to 12 significant digits (the record's size)."""
    if isinstance(value, dict):
        return {key: _canonical(item) for key, item in value.items() if key != 'seconds'}
    if isinstance(value, list):
        return [_canonical(item) for item in value]
    if isinstance(value, float):
        return float(f'{value:.12g}')
    return value


def analyze_documents() -> Dict[str, Any]:
    """Run ``baseball-collision analyze --json`` per run; return {run: canonical document}."""
    script = Path(sys.executable).parent / 'baseball-collision'
    documents = {}
    with tempfile.TemporaryDirectory() as directory:
        for name, flags in RUNS.items():
            bags = [f'bags/{bag}' for bag in (BAGS[:1] if name == 'predict' else BAGS)]
            out = Path(directory) / f'{name}.json'
            subprocess.run([str(script), 'analyze', *bags, *flags, '--json', str(out)],
                           cwd=REPO_ROOT, check=True, stdout=subprocess.DEVNULL,
                           env={**os.environ, 'COLUMNS': '200'})
            documents[name] = _canonical(json.loads(out.read_text()))
    return documents


def main() -> None:
    """Print or (``--write``) record the documents."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--write', action='store_true', help=f'record into {BASELINE.name}')
    documents = analyze_documents()
    if parser.parse_args().write:
        BASELINE.write_text(json.dumps(documents, indent=None, separators=(',', ':')) + '\n')
    else:
        json.dump(documents, sys.stdout, indent=1)


if __name__ == '__main__':
    main()
