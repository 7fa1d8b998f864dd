"""
``baseball-collision demo``: a live ``impact_node`` fed by a bundled bag over DDS.

The demo runs, on an isolated DDS domain (a random ``ROS_DOMAIN_ID``, discovery limited to this
host):

1. ``impact_node`` as a subprocess (the venv's console script) with a bundled parameter file,
   ``use_sim_time`` and reliable keep-all subscriptions (``qos:=reliable_all``: a replay must
   not lose a message, however far behind a loaded machine leaves the node);
2. in this process, a :class:`~baseball_collision.ros.replay.BagPlayer` that waits for the
   node's subscriptions, then replays the bag with ``/clock``, and subscriptions to the node's
   ``~/impact``, ``~/impact_report`` and ``~/near_miss`` that print each event as it arrives
   (the rclpy side, :class:`~baseball_collision.ros.listener.EventListener`, hands them to
   :class:`LiveEvents` as plain values: this module imports no rclpy);
3. a summary: the live impacts against the bag's truth file, and against ``analyze`` run
   offline on the same bag with the same parameters (the stamps must be identical);
4. the node is stopped with SIGINT (as Ctrl-C would) and its exit code checked.

Exit code 0 when the node ran and stopped cleanly, reported impacts and agreed with the offline
analysis; 1 otherwise.
"""

from dataclasses import dataclass
import json
import math
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Any, Callable, Dict, IO, List, Optional

from .analyze import AnalysisOptions, analyze_bag, BagAnalysis
from .parameters import load_parameters, NODE_NAME, output_topics
from .report import truth_line
from .truth import compare_truth, load_truth
from ..core.detector import MPS_TO_MPH
from ..core.geometry import norm, Vector
from ..errors import RosError, ToolError, TopicError

PACKAGE = 'baseball_collision'
DEMO_BAG = 'bags/pitches_360hz.mcap'
"""The bundled bag the demo replays (relative to the package's source or share directory)."""

DEMO_PARAMS = 'config/impact_node.yaml'
"""The bundled parameter file the node and the offline analysis read."""

NODE_OVERRIDES = ('use_sim_time:=true', 'qos:=reliable_all')
"""``-p`` overrides given to the node on top of the parameter file (transport only)."""

CATCH_UP_S = 5.0
"""After the replay, how long (s) the demo waits for the node's next impact before it sums up
(a node on a loaded machine works through its queue long after the replay ended)."""

MATCH_SETTLE_S = 0.5
"""How long (s) ``wait_for_node`` waits on once our side sees the node's topics matched, for the
node's own side to match ours before the replay starts."""


def bundled(relative: str) -> Path:
    """
    Return a bundled file: from the source tree, else the installed share directory.

    :raises ToolError: found in neither.
    """
    source = Path(__file__).resolve().parents[2] / relative
    if source.exists():
        return source
    try:
        from ament_index_python.packages import get_package_share_directory
        share = Path(get_package_share_directory(PACKAGE)) / relative
    except (ImportError, LookupError, ValueError):
        share = None
    if share is not None and share.exists():
        return share
    raise ToolError(f'bundled file {relative} not found (looked in {source.parent} and the '
                    f'{PACKAGE} share directory)')


def node_command(params: Path) -> List[str]:
    """Return the command that starts ``impact_node`` with ``params`` and the demo overrides."""
    script = Path(sys.executable).parent / 'impact_node'
    start = [str(script)] if script.exists() else [sys.executable, '-m', f'{PACKAGE}.ros.node']
    overrides = [arg for override in NODE_OVERRIDES for arg in ('-p', override)]
    return start + ['--ros-args', '--params-file', str(params)] + overrides


def isolated_environment(domain: Optional[int] = None) -> Dict[str, str]:
    """Return os.environ for a private DDS domain on this host (random id 1-101 by default)."""
    env = dict(os.environ)
    env.pop('RMW_IMPLEMENTATION', None)
    env['ROS_DOMAIN_ID'] = str(domain if domain is not None
                               else random.SystemRandom().randint(1, 101))
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    return env


# ----------------------------------------------------------------------------------------------
# Reading what the node says


@dataclass
class LiveImpact:
    """
    An impact as the node published it: its ``~/impact`` and its ``~/impact_report`` record.

    :ivar stamp_ns: the impact instant (``~/impact`` header stamp).
    :ivar point: contact point (m).
    :ivar distance_from_tip_m: the impact's place along the axis from the tip, within the
        profile's ends (m): the spot the truth files give (an end cap's station for its hits),
        from the record's ``bat_fraction``, knob and tip.
    :ivar contact_from_tip_m: the contact point's own distance from the tip along the axis
        (m): the record's ``distance_from_tip_m`` (what is printed).
    :ivar sweet_spot_speed_mps: the record's sweet-spot speed (m/s).
    :ivar bat_speed_mps: the record's bat speed at the contact point (m/s).
    :ivar reported: its record has come (the numbers above are the node's).
    """

    stamp_ns: int
    point: Optional[Vector] = None
    distance_from_tip_m: float = math.nan
    contact_from_tip_m: float = math.nan
    sweet_spot_speed_mps: float = math.nan
    bat_speed_mps: float = math.nan
    reported: bool = False

    def take_record(self, record: Dict[str, Any]) -> None:
        """Take the numbers of the impact's ``~/impact_report`` record (a parsed JSON dict)."""
        length = math.dist(record['knob'], record['tip'])
        self.distance_from_tip_m = (1.0 - record['bat_fraction']) * length
        self.contact_from_tip_m = record['distance_from_tip_m']
        self.sweet_spot_speed_mps = record['sweet_spot_speed_mps']
        self.bat_speed_mps = record['bat_speed_at_contact_mps']
        self.reported = True


@dataclass
class LiveNearMiss:
    """A near miss as the node published it: stamp (ns) and gap vector (m)."""

    stamp_ns: int
    gap_vector: Vector


class LiveEvents:
    """
    The node's events as they arrive; each printed once complete.

    An impact is complete when both its ``~/impact`` message and its ``~/impact_report`` record
    (same stamp) arrived: it is printed with the record's numbers, the node's own. The ``on_*``
    methods may be called from another thread.

    :param first_ns: the bag's first stamp (ns): printed times are seconds from it.
    :param out: where to print.
    """

    def __init__(self, first_ns: int, out: IO[str]) -> None:
        self.first_ns = first_ns
        self.out = out
        self.lock = threading.Lock()
        self.impacts: Dict[int, LiveImpact] = {}
        self.printed: List[LiveImpact] = []
        self.near_misses: List[LiveNearMiss] = []

    def _impact(self, stamp_ns: int) -> LiveImpact:
        return self.impacts.setdefault(stamp_ns, LiveImpact(stamp_ns))

    def on_impact(self, stamp_ns: int, point: Vector) -> None:
        """Take an ``~/impact`` message: stamp (ns) and contact point (m)."""
        with self.lock:
            self._impact(stamp_ns).point = point
            self._complete(stamp_ns)

    def on_report(self, text: str) -> None:
        """Take an ``~/impact_report`` record (JSON text); an impact's completes its impact."""
        record = json.loads(text)
        if record.get('event') != 'impact':
            return
        with self.lock:
            self._impact(record['stamp_ns']).take_record(record)
            self._complete(record['stamp_ns'])

    def _complete(self, stamp: int) -> None:
        impact = self.impacts[stamp]
        if impact.point is None or not impact.reported or impact in self.printed:
            return
        self.printed.append(impact)
        self.out.write(
            f'  impact     {(stamp - self.first_ns) * 1e-9:8.4f} s  (stamp {stamp})  '
            f'{impact.contact_from_tip_m * 100:5.1f} cm from the tip, sweet spot '
            f'{impact.sweet_spot_speed_mps * MPS_TO_MPH:5.1f} mph, bat at contact '
            f'{impact.bat_speed_mps * MPS_TO_MPH:5.1f} mph\n')
        self.out.flush()

    def on_near_miss(self, stamp_ns: int, vector: Vector) -> None:
        """Take a ``~/near_miss`` message: stamp (ns) and gap vector (m)."""
        with self.lock:
            self.near_misses.append(LiveNearMiss(stamp_ns, vector))
            where = 'over' if vector[2] > 0.0 else 'under'
            self.out.write(f'  near miss  {(stamp_ns - self.first_ns) * 1e-9:8.4f} s  (stamp '
                           f'{stamp_ns})  the ball passed {norm(vector) * 100:5.1f} cm from the '
                           f'bat ({where} it)\n')
            self.out.flush()

    def complete_impacts(self) -> List[LiveImpact]:
        """Return the impacts received with their records, in stamp order."""
        with self.lock:
            return sorted(self.printed, key=lambda impact: impact.stamp_ns)


# ----------------------------------------------------------------------------------------------
# Running it


def stop_node(process: 'subprocess.Popen[bytes]', timeout_s: float = 10.0) -> int:
    """Stop the node as Ctrl-C would (SIGINT); escalate if it hangs. Return its exit code."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            return process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            process.terminate()
            try:
                process.wait(5.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
            return process.returncode if process.returncode else -signal.SIGKILL
    return process.returncode


def wait_for_node(process: 'subprocess.Popen[bytes]', player: Any, topics: List[str],
                  ready: Callable[[], bool], timeout_s: float) -> Optional[str]:
    """
    Wait until the node subscribes to ``topics`` of the player and ``ready()`` holds.

    :param process: the node's process (its early exit ends the wait).
    :param player: the :class:`~baseball_collision.ros.replay.BagPlayer`.
    :param topics: the input topics the node must subscribe to.
    :param ready: e.g. whether our subscriptions matched the node's publishers.
    :param timeout_s: longest wait (s).
    :returns: None when ready, else what went wrong (one line).

    Ready is what our side sees: DDS matches a publisher and a subscription on each side
    apart, and a message the node publishes before its own side has matched ours is lost (the
    outputs are volatile); so once ready, the wait goes on for ``MATCH_SETTLE_S`` and checks
    again (a bag's first impact comes 30-60 ms into a replay at 4-8x).
    """
    deadline = time.monotonic() + timeout_s
    while True:
        if process.poll() is not None:
            return f'{NODE_NAME} exited early with code {process.returncode}'
        try:
            player.wait_for_subscribers(topics, 0.2)
            if ready():
                time.sleep(MATCH_SETTLE_S)
                if ready() and process.poll() is None:
                    return None
            time.sleep(0.05)
        except RosError:
            pass
        if time.monotonic() > deadline:
            return (f'{NODE_NAME} did not subscribe to {", ".join(topics)} and publish within '
                    f'{timeout_s:.0f} s')


def _tail(log: Path, lines: int = 15) -> str:
    try:
        text = log.read_text(errors='replace').strip().splitlines()
    except OSError:
        return ''
    return '\n'.join('    ' + line for line in text[-lines:])


def run_demo(bag: Optional[Path] = None, params: Optional[Path] = None, rate: float = 4.0,
             timeout_s: float = 30.0, out: IO[str] = sys.stdout,
             domain: Optional[int] = None) -> int:
    """
    Run the demo (see the module docstring).

    :param bag: the bag to replay; None: the bundled :data:`DEMO_BAG`.
    :param params: the node's parameter file; None: the bundled :data:`DEMO_PARAMS`.
    :param rate: replay speed factor.
    :param timeout_s: longest wait for the node to come up (s).
    :param out: where to print.
    :param domain: the ROS_DOMAIN_ID to run on; None: a random one (1-101).
    :returns: the exit code: 0 on success, 1 when the node failed or disagreed.
    :raises ToolError: missing files, or a bag or parameter file that cannot be used.
    """
    bag = Path(bag) if bag is not None else bundled(DEMO_BAG)
    params = Path(params) if params is not None else bundled(DEMO_PARAMS)
    try:
        offline = analyze_bag(bag, AnalysisOptions(parameters=load_parameters(params),
                                                   topic_flags=False), progress=False)
    except ToolError as error:  # the demo has no topic flags: the bag's topics are replayed
        if not isinstance(error.__cause__, TopicError):
            raise
        raise ToolError(f"{error} (the demo replays {bag.name}'s own topics: give --params a "
                        "file whose topics are the bag's)") from error
    env = isolated_environment(domain)
    os.environ.update({key: env[key] for key in ('ROS_DOMAIN_ID',
                                                 'ROS_AUTOMATIC_DISCOVERY_RANGE')})
    os.environ.pop('RMW_IMPLEMENTATION', None)
    command = node_command(params)
    with tempfile.TemporaryDirectory(prefix='baseball_collision_demo.') as tmp:
        log = Path(tmp) / 'impact_node.log'
        with open(log, 'wb') as log_file:
            shown = ' '.join([Path(command[0]).name] + command[1:])
            out.write(f'starting {NODE_NAME} on DDS domain {env["ROS_DOMAIN_ID"]} (this host '
                      f'only): {shown}\n')
            out.flush()
            process = subprocess.Popen(command, env=env, stdout=log_file,
                                       stderr=subprocess.STDOUT)
            try:
                code = _live(process, bag, offline, rate, timeout_s, out, log)
            finally:
                node_code = stop_node(process)
        if node_code != 0:
            out.write(f'{NODE_NAME} exited with code {node_code}; its log:\n{_tail(log)}\n')
            return 1
        out.write(f'{NODE_NAME} stopped cleanly (exit code 0)\n')
    return code


def _live(process: 'subprocess.Popen[bytes]', bag: Path, offline: BagAnalysis,
          rate: float, timeout_s: float, out: IO[str], log: Path) -> int:
    """Replay into the running node, collect its events, print the summary; return the code."""
    from ..ros.listener import EventListener, RosSession
    from ..ros.replay import BagPlayer, LATE_WARN_S, replay_summary

    stop = threading.Event()
    with RosSession('impact_demo') as session:
        try:
            events = LiveEvents(offline.first_stamp_ns or 0, out)
            listener = EventListener(session.node, output_topics(NODE_NAME), events.on_impact,
                                     events.on_report, events.on_near_miss)
            with BagPlayer(session.node, bag, rate=rate) as player:
                inputs = list(offline.selection.topics.values())
                problem = wait_for_node(process, player, inputs, listener.matched, timeout_s)
                if problem is not None:
                    out.write(f'{problem}; its log:\n{_tail(log)}\n')
                    return 1
                length = (offline.stats.newest_stamp_ns or 0) - (offline.first_stamp_ns or 0)
                out.write(f'{NODE_NAME} is listening; replaying {bag.name} ({length * 1e-9:.1f} '
                          f's, {player.message_count:,} messages on '
                          f'{", ".join(player.topics)}) at {rate:g}x with /clock\n')
                out.flush()
                result = player.play(stop=stop)
            expected = len(offline.impacts)
            seen, deadline = -1, 0.0
            while True:  # the node may still be catching up on its queue (keep-all)
                count = len(events.complete_impacts())
                if count >= expected:
                    break
                if count != seen:
                    seen, deadline = count, time.monotonic() + CATCH_UP_S
                elif time.monotonic() >= deadline:
                    break
                time.sleep(0.05)
            time.sleep(0.3)  # anything beyond the offline count would arrive now
            if result.ack_timeouts or result.late_s > LATE_WARN_S or \
                    result.keep_last_subscribers or result.best_effort_subscribers:
                out.write(f'replay: {replay_summary(result, player.message_count, False)}\n')
            return _summary(events, offline, result.seconds, out)
        finally:
            stop.set()


def _summary(events: LiveEvents, offline: BagAnalysis, seconds: float, out: IO[str]) -> int:
    """Print the live results against truth and the offline analysis; return the exit code."""
    impacts = events.complete_impacts()
    misses = list(events.near_misses)
    out.write(f'live: {len(impacts)} impacts and {len(misses)} near misses from {NODE_NAME} '
              f'({seconds:.1f} s of replay)\n')
    if offline.truth is not None:
        truth = load_truth(offline.truth.path)
        comparison = compare_truth(impacts, misses, truth, offline.truth.path)
        out.write(f'  {truth_line(comparison)}\n')
    live = [impact.stamp_ns for impact in impacts]
    stamps = [impact.stamp_ns for impact in offline.impacts]
    if live == stamps:
        out.write(f'  offline analyze, same bag and parameters ({offline.config.model} model): '
                  f'{len(stamps)} impacts, stamps identical to the live node\n')
    else:
        out.write(f'  offline analyze disagrees: live stamps {live}, offline {stamps}\n')
    ok = bool(impacts) and live == stamps
    return 0 if ok else 1
