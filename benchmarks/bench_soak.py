"""
Soak benchmark: impact_node at 1 kHz per stream for minutes; memory, processing, backlog, truth.

Run: ``.venv/bin/python benchmarks/bench_soak.py [--minutes 10] [--rate 1000] [--qos reliable]``.

The harness is ``test/support/soak.py`` (shared with the short soak test, which asserts only
what does not depend on the machine: every impact found, nothing lost or false, no drop or
reset). This prints its figures (see that module) and checks them against the limits below,
which are wall-clock figures of this machine, not test assertions.
"""

import argparse
from pathlib import Path
import sys
from typing import List, Optional, Tuple

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
from support.soak import run_soak, Soak  # noqa: E402, I100 - test/ is not a package

P99_LIMIT_MS = 1.0
"""Processing p99 per message callback (ms) the node should stay within."""

RSS_GROWTH_LIMIT_MB = 5.0
"""Growth of the node's RSS over the run (MB) that still counts as flat."""

LATENCY_LIMIT_MS = 500.0
"""Largest impact latency (completing publish -> ~/impact received, ms)."""

LATENCY_DRIFT_LIMIT_MS = 20.0
"""Largest growth of the median latency from the first tenth of the run to the last (ms)."""

WATERMARK_LAG_LIMIT = 200
"""Most samples published beyond the node's watermark at a /diagnostics status (backlog)."""


def limits(soak: Soak) -> List[Tuple[str, bool]]:
    """Return each wall-clock limit as (what, met)."""
    first, last = soak.latency_tenths() if soak.latencies_ms else (0.0, 0.0)
    return [
        (f"processing p99 {soak.node.get('p99', float('nan')):.3f} ms <= {P99_LIMIT_MS} ms",
         soak.node.get('p99', float('inf')) <= P99_LIMIT_MS),
        (f'RSS growth {soak.growth_mb:+.2f} MB < {RSS_GROWTH_LIMIT_MB} MB',
         soak.growth_mb < RSS_GROWTH_LIMIT_MB),
        (f'latency max {max(soak.latencies_ms, default=0.0):.1f} ms < {LATENCY_LIMIT_MS} ms',
         max(soak.latencies_ms, default=0.0) < LATENCY_LIMIT_MS),
        (f'latency median last tenth {last:.2f} ms < first tenth {first:.2f} ms + '
         f'{LATENCY_DRIFT_LIMIT_MS} ms', last < first + LATENCY_DRIFT_LIMIT_MS),
        (f'watermark lag {soak.watermark_lag_max} < {WATERMARK_LAG_LIMIT} samples',
         soak.watermark_lag_max < WATERMARK_LAG_LIMIT),
    ]


def main(argv: Optional[List[str]] = None) -> int:
    """Parse the command line, run the soak, print its figures and limits; 1 if one is missed."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--minutes', type=float, default=10.0, help='duration (10)')
    parser.add_argument('--rate', type=float, default=1000.0, help='Hz per stream (1000)')
    parser.add_argument('--qos', choices=('reliable', 'sensor_data'), default='reliable',
                        help='node input QoS and publisher reliability (reliable)')
    parser.add_argument('--seed', type=int, default=7, help='scenario seed (7)')
    parser.add_argument('--tolerance-us', type=float, default=100.0,
                        help='largest impact stamp error that matches the truth (100)')
    args = parser.parse_args(argv)
    soak = run_soak(args.minutes * 60.0, args.rate, args.qos, args.seed, args.tolerance_us,
                    progress=True)
    print(soak.report())
    for line in soak.warnings[:10]:
        print('  warning:', line)
    checks = limits(soak)
    for what, met in checks:
        print(f"  limit: {what}: {'ok' if met else 'MISSED'}")
    return 0 if all(met for _, met in checks) else 1


if __name__ == '__main__':
    sys.exit(main())
