"""
The ``baseball-collision`` command line.

Subcommands grow with the package; ``demo`` is the README's main job.
"""

import argparse
import sys
from typing import List, Optional

from .bat import WOOD_BAT_34
from .solver import seed_time_of_impact, time_of_impact, time_of_impact_profile

BALL_RADIUS = 0.0366  # metres, a regulation baseball (9.2 in circumference)

# One frame at 90 Hz of a real-looking swing: knob near the hands, barrel turning through the
# zone, and a pitch crossing it. Positions in metres.
_EXAMPLES = (
    ('barrel hit between frames',
     ([-0.4919, 0.2479, 0.0042], [-0.4623, -0.1882, 0.0608], [-0.7640, -0.3312, 0.0161],
      [-0.8315, 0.0461, -0.0119], [0.0066, 0.0029, -0.0001], [0.0072, -0.0004, 0.0001])),
    ('ball passing 10 cm beyond the tip',
     ([1.00, 0.60, 0.0], [1.00, -0.60, 0.0], [0.8636, 0.0, 0.0], [0.8636, 0.0, 0.0],
      [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])),
)


def _demo(args: argparse.Namespace) -> int:
    dt = 1.0 / 90.0
    print('baseball_collision demo: exact time of impact inside one 90 Hz frame (11.1 ms)')
    for title, points in _EXAMPLES:
        exact = time_of_impact_profile(*points, BALL_RADIUS, WOOD_BAT_34, dt)
        capsule = time_of_impact(*points, BALL_RADIUS, WOOD_BAT_34.max_radius, dt)
        seed = seed_time_of_impact(*points, BALL_RADIUS, WOOD_BAT_34.max_radius, dt)
        print(f'\n{title}:')
        if exact is None:
            print('  wood-bat profile: no contact')
        else:
            from_tip = (1.0 - exact.bat_fraction) * WOOD_BAT_34.length
            print(f'  wood-bat profile: contact at {exact.time * 1e3:.3f} ms, '
                  f'{from_tip * 100:.1f} cm from the tip ({exact.feature})')
        print('  capsule (barrel radius): '
              + ('no contact' if capsule is None else f'contact at {capsule.time * 1e3:.3f} ms'))
        print('  seed (infinite line):    '
              + ('no contact' if seed is None else f'contact at {seed * 1e3:.3f} ms'))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog='baseball-collision',
        description='Find the instant a tracked bat hits a tracked ball.')
    commands = parser.add_subparsers(dest='command', required=True)
    demo = commands.add_parser('demo', help='run the main job on a bundled example')
    demo.set_defaults(run=_demo)
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    """Run the command line; returns the process exit code."""
    args = build_parser().parse_args(argv)
    return args.run(args)


if __name__ == '__main__':
    sys.exit(main())
