"""
What a marker array costs the node's thread: messages made and converted, or CDR bytes packed.

Run: ``.venv/bin/python benchmarks/bench_markers.py [--repeats N]``.

The node publishes ``~/markers`` at every impact (the bat's profile pieces, the ball, the
contact, the normal and a label: ``core.scene.impact_scene``) and refreshes the live bat and ball
``marker_rate`` times a second (``live_scene``), in its executor's thread. Publishing a
``MarkerArray`` message makes rclpy convert it into a C message and serialise it; the node
instead publishes the bytes ``markers.scene_cdr`` packs (rclpy sends bytes as they are). This
times, on a simulated impact's scene and a live scene, the messages made (``scene_markers``) and
serialised by rclpy (``rclpy.serialization.serialize_message``: the conversion and serialisation
a publish does) against ``scene_cdr``, each N times in turn, and prints the medians (us, the
thread's CPU clock) and their ratio. Both give the same message (``test/ros/test_markers.py``).
"""

import argparse
import time
from typing import Callable, List

from baseball_collision.core.detector import DetectorConfig, Impact
from baseball_collision.core.scene import impact_scene, live_scene, Scene
from baseball_collision.ros.markers import scene_cdr, scene_markers
from baseball_collision.tools.accuracy import run_samples
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
from rclpy.serialization import serialize_message


def _scenes() -> List[Scene]:
    """Return a simulated barrel hit's impact scene and a live scene of its last samples."""
    config = DetectorConfig(bat_input='points', model='c2')
    scenario = make_scenario('barrel', np.random.default_rng(1))
    samples = sample(scenario, 360.0, np.random.default_rng(2))
    events, _ = run_samples(scenario, samples, config)
    impact = next(e for e in events if isinstance(e, Impact))
    live = live_scene(impact.stamp_ns, 'world', impact.ball_position, (impact.knob, impact.tip),
                      config, 0.1)
    return [impact_scene(impact, 'world', config, 5.0), live]


def _median_us(call: Callable[[], object], repeats: int) -> float:
    """Return the median CPU time (us) of ``call`` over ``repeats`` calls."""
    times = []
    for _ in range(repeats):
        start = time.thread_time()
        call()
        times.append(time.thread_time() - start)
    return float(np.median(times) * 1e6)


def main() -> None:
    """Time both ways on both scenes, in turn, and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0].strip())
    parser.add_argument('--repeats', type=int, default=2000)
    args = parser.parse_args()
    for name, scene in zip(('an impact', 'the live bat and ball'), _scenes()):
        made = _median_us(lambda: serialize_message(scene_markers(scene)), args.repeats)
        packed = _median_us(lambda: scene_cdr(scene), args.repeats)
        print(f'{name} ({len(scene.items)} markers): messages made and serialised '
              f'{made:7.1f} us, CDR packed {packed:6.1f} us: {made / packed:5.1f}x')


if __name__ == '__main__':
    main()
