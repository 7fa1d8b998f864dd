"""
The ``baseball-collision`` command line: ``simulate``, ``analyze``, ``replay`` and ``demo``.

* ``simulate OUT``: a bag of simulated pitches and swings with its truth file
  (:mod:`baseball_collision.tools.recording`).
* ``analyze BAG [BAG ...]``: the detector over recorded bags (``--jobs`` at a time, one process
  each), with one table, JSON, CSV, plots and an output bag
  (:mod:`baseball_collision.tools.analyze`, ``report``, ``plots``; no rclpy needed).
* ``replay BAG``: publish a bag over ROS 2 with ``/clock`` (:mod:`baseball_collision.ros.replay`).
* ``demo``: a live ``impact_node`` fed by a bundled bag (:mod:`baseball_collision.tools.demo`).

Bad input (missing or corrupt bags, missing topics, existing outputs, bad values) ends with one
line ``baseball-collision: error: ...`` on stderr and exit code 2, and no output file written.
rclpy is imported only by ``replay`` and ``demo``.
"""

import argparse
import math
from pathlib import Path
import shlex
import shutil
import sys
import time
from typing import Any, Callable, List, NoReturn, Optional, Tuple

from .choices import BAT_CHOICES, FAMILIES, KINDS, MAX_RATE_HZ, MAX_SEED, NOISE_ON
from .ending import end_process
from .outputs import Outputs
from .parameters import load_parameters, NODE_NAME, Remapping
from .truth import truth_path
from .. import __version__
from ..atomic import cleanup_on_signals, Terminated
from ..bags import TOPIC_FLAGS
from ..core.motion import MODELS
from ..errors import BaseballCollisionError, ToolError
from ..threads import single_threaded_blas

PROG = 'baseball-collision'
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130

PIP_NAMES = {'yaml': 'PyYAML', 'rclpy': "'ros-jazzy-rclpy[fastrtps]' (or source ROS 2 Jazzy)"}
"""What to install for a missing module (the module's own name otherwise)."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line: ``baseball-collision: error: ...``."""

    def error(self, message: str) -> NoReturn:
        """Print the error in one line with a pointer to ``--help``; exit with code 2."""
        sys.stderr.write(f'{PROG}: error: {message} (see {self.prog} --help)\n')
        sys.exit(EXIT_BAD_INPUT)


class _Command(_Parser):
    """
    A subcommand's parser: its own errors (pointing to its own ``--help``), options anywhere.

    argparse hands a subcommand the arguments after its name and, of what it does not take,
    lets the top-level parser complain, pointing to the top-level help; here the subcommand
    refuses them itself. With :attr:`intermixed` (``analyze``) options may also stand between
    the positionals (``analyze A.mcap --json o.json B.mcap``): argparse's intermixed parsing,
    ``--`` still ending the options (:meth:`_parse_intermixed`). An unknown option is named
    alone in the error, not with the positionals after it (``unrecognized arguments: --bogus``).
    """

    intermixed = False
    """Parse options between positionals (``parse_known_intermixed_args``)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._parsing = False

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:
        """Parse a subcommand's arguments; anything left over is this subcommand's error."""
        if self._parsing:  # (the intermixed parse's own passes)
            return super().parse_known_args(args, namespace)
        self._parsing = True
        try:
            if self.intermixed:
                args = list(sys.argv[1:] if args is None else args)
                namespace, extras = self._parse_intermixed(args, namespace)
            else:
                namespace, extras = super().parse_known_args(args, namespace)
        finally:
            self._parsing = False
        if extras:  # (intermixed: positionals after an unknown option are left too)
            options = [extra for extra in extras if extra.startswith('-')] \
                if self.intermixed else []
            self.error(f"unrecognized arguments: {' '.join(options or extras)}")
        return namespace, extras

    def _parse_intermixed(self, args: List[str], namespace: Any) -> Tuple[Any, List[str]]:
        """
        Parse options anywhere among the positionals; what follows ``--`` is positional.

        argparse's intermixed parsing reads an option after ``--`` as one when no positional
        stands before it (``analyze -- a.mcap --json o.json`` wrote o.json): here the arguments
        after the first ``--`` are added to the last positional (``analyze``'s bags) as they
        are, and only those before it are parsed.

        :returns: the namespace and the arguments not taken.
        """
        if '--' not in args:
            return super().parse_known_intermixed_args(args, namespace)
        cut = args.index('--')
        head, tail = args[:cut], args[cut + 1:]
        last = self._get_positional_actions()[-1]
        saved = last.nargs
        if tail and saved == '+':
            last.nargs = '*'  # (the positionals after -- count too)
        try:
            namespace, extras = super().parse_known_intermixed_args(head, namespace)
        finally:
            last.nargs = saved
        if tail:
            setattr(namespace, last.dest, list(getattr(namespace, last.dest, None) or []) + tail)
        return namespace, extras


def _number(minimum: float, inclusive: bool, what: str,
            maximum: float = math.inf) -> Callable[[str], float]:
    """Return an argparse type: a finite float above ``minimum`` (or at it if inclusive)."""
    def convert(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number ({what})") from None
        if not math.isfinite(value) or value < minimum or (value == minimum and not inclusive):
            bound = f'>= {minimum:g}' if inclusive else f'> {minimum:g}'
            raise argparse.ArgumentTypeError(f"'{text}' must be a finite number {bound} "
                                             f'({what})')
        if value > maximum:
            raise argparse.ArgumentTypeError(f"'{text}' must be at most {maximum:g} ({what})")
        return value
    return convert


def _whole(text: str) -> int:
    """Return ``text`` as an int, or raise the argparse error saying it is not one."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None


def _domain(text: str) -> int:
    """Return a ROS domain id: a whole number 0-101 (the ids whose DDS ports are safe)."""
    value = _whole(text)
    if not 0 <= value <= 101:
        raise argparse.ArgumentTypeError(f"'{text}' must be a ROS domain id from 0 to 101")
    return value


def _seed(text: str) -> int:
    value = _whole(text)
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"'{text}' must be from 0 to 2^64 - 1")
    return value


def _count(text: str) -> int:
    value = _whole(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"'{text}' must be >= 1")
    return value


def _factor(text: str) -> int:
    value = _whole(text)
    if value < 2:
        raise argparse.ArgumentTypeError(f"'{text}' must be >= 2 (every K-th frame)")
    return value


def _kinds(text: str) -> List[str]:
    kinds = [kind.strip() for kind in text.split(',') if kind.strip()]
    unknown = [kind for kind in kinds if kind not in KINDS]
    if not kinds or unknown:
        named = ', '.join(unknown) if unknown else repr(text)
        raise argparse.ArgumentTypeError(
            f"unknown kind(s) {named}; choose from {', '.join(KINDS)}")
    return kinds


# ----------------------------------------------------------------------------------------------
# simulate


def _simulate(args: argparse.Namespace) -> int:
    from .recording import RecordingSpec, write_recording
    spec = RecordingSpec(
        count=args.count, kinds=tuple(args.kinds), rate_hz=args.rate, jitter_s=args.jitter,
        grid_s=args.grid, noise_m=args.noise, spacing_s=args.spacing, seed=args.seed,
        frame_id=args.frame_id, bat=args.bat, unique=args.unique, family=args.family,
        ball_rate_hz=args.ball_rate, noise_on=args.noise_on, marker_spread_m=args.marker_spread,
        spin=args.spin, plan_hz=args.plan)
    command = shlex.join([PROG] + list(args.argv))
    document = write_recording(args.out, spec, storage=args.storage, command=command)
    contacts = sum(1 for pitch in document['pitches'] if pitch['contact'])
    print(f"wrote {args.out}: {document['messages']:,} messages, {spec.count} pitches "
          f'({contacts} with contact) at {spec.rate_hz:g} Hz'
          + ('' if spec.ball_rate_hz is None else f', the ball at {spec.ball_rate_hz:g} Hz')
          + f" on {', '.join(document['topics'].values())}; truth in "
          f'{truth_path(args.out)}')
    return 0


# ----------------------------------------------------------------------------------------------
# analyze


def _keep_going_hint(args: argparse.Namespace) -> str:
    """Return what to add to the error that ended a run over several bags ('' for one bag)."""
    from .many_bags import bag_paths
    if args.keep_going or args.out_bag:  # (--out-bag takes one bag)
        return ''
    try:
        several = len(bag_paths(args.bags)) > 1
    except ToolError:  # (no bags at all: the error says so)
        return ''
    return ' (--keep-going skips a bag that cannot be analysed and goes on with the others)' \
        if several else ''


def terminal_width() -> Optional[int]:
    """
    Return the columns of the terminal standard output shows in (``COLUMNS`` first), or None.

    None where standard output is no terminal (a pipe, a file): the report keeps its full
    table and long lines there, the same whatever the terminal that started the command.
    """
    return shutil.get_terminal_size().columns if sys.stdout.isatty() else None


def _analyze(args: argparse.Namespace) -> int:
    from .analyze import AnalysisOptions, BagAnalysis
    from .many_bags import analyze_bags
    from .report import (csv_text, fitted, format_report, json_text, season_lines,
                         total_line)
    node = Remapping.parse(args.remap, args.node_name).node_name  # (__node, __ns applied)
    parameters = load_parameters(args.params, node) if args.params else {}
    options = AnalysisOptions(
        ball_topic=args.ball_topic, bat_pose_topic=args.bat_pose_topic,
        knob_topic=args.knob_topic, tip_topic=args.tip_topic, parameters=parameters,
        model=args.model, ball_radius=args.ball_radius, bat_radius=args.bat_radius,
        prediction_horizon=args.predict, node_name=args.node_name,
        bat_plan_topic=args.bat_plan_topic, remaps=tuple(args.remap),
        decimate=tuple(dict.fromkeys(args.decimate)))
    start = time.perf_counter()
    skipped: Optional[List[Tuple[Path, str]]] = [] if args.keep_going else None
    to_stdout = [flag for flag, value in (('json', args.json), ('csv', args.csv)) if value == '-']
    if len(to_stdout) > 1:
        raise ToolError('only one of --json and --csv can be - (standard output)')
    json_file, csv_file = (None if value == '-' else value for value in (args.json, args.csv))
    with Outputs(json=json_file, csv=csv_file, plot=args.plot, out_bag=args.out_bag) as outputs:
        writer = outputs.bag_writer('out_bag', 'mcap') if args.out_bag else None
        try:
            analyses: List[BagAnalysis] = analyze_bags(
                args.bags, options, jobs=args.jobs, out_bag=writer,
                progress=not args.no_progress, use_truth=not args.no_truth, skipped=skipped)
        except ToolError as error:
            raise ToolError(f'{error}{_keep_going_hint(args)}') from error
        for analysis in list(analyses):
            silenced = analysis.silenced_topics()
            if silenced and skipped is None:
                raise ToolError(f"{analysis.path}: {'; '.join(silenced)}{_keep_going_hint(args)}")
            if silenced:
                skipped.append((analysis.path, f"{analysis.path}: {'; '.join(silenced)}"))
                analyses.remove(analysis)
        for _, why in skipped or ():
            print(f'{PROG}: skipped: {why}', file=sys.stderr)
        if skipped and not analyses:
            raise ToolError(f'no bag could be analysed ({len(skipped)} skipped)')
        document = {'plots': bool(args.plot), 'skipped': skipped}
        if json_file:
            outputs.stage_text('json', json_text(analyses, **document))
        if csv_file:
            outputs.stage_text('csv', csv_text(analyses))
        if args.plot:
            from .plots import write_plots
            outputs.stage_directory('plot', lambda directory: write_plots(
                analyses, directory, jobs=args.jobs, progress=not args.no_progress))
        outputs.commit()
    if to_stdout:  # the document alone on standard output, for a pipe
        sys.stdout.write(json_text(analyses, **document) if args.json == '-'
                         else csv_text(analyses))
    elif not args.quiet:
        width = terminal_width()
        print('\n\n'.join(format_report(analysis, width) for analysis in analyses))
        if len(analyses) > 1:
            total = total_line(analyses, wall_s=time.perf_counter() - start)
            print('\n' + '\n'.join(fitted([total, *season_lines(analyses)], width)))
    return EXIT_BAD_INPUT if skipped else 0


# ----------------------------------------------------------------------------------------------
# replay and demo (rclpy)


def _replay(args: argparse.Namespace) -> int:
    from ..ros.replay import run_replay

    return run_replay(args.bag, rate=args.rate, loop=args.loop, clock_hz=args.clock,
                      wait_for=args.wait_for, wait_timeout_s=args.wait_timeout)


def _demo(args: argparse.Namespace) -> int:
    from .demo import run_demo
    return run_demo(args.bag, args.params, rate=args.rate, timeout_s=args.timeout,
                    domain=args.domain)


# ----------------------------------------------------------------------------------------------
# parser


def _add_topic_flags(parser: argparse.ArgumentParser) -> None:
    for role, help_text in (
            ('ball', 'ball topic (PointStamped or PoseStamped)'),
            ('bat_pose', 'bat pose topic (PoseStamped)'),
            ('knob', 'knob end topic (PointStamped; with the tip topic)'),
            ('tip', 'barrel end topic (PointStamped; with the knob topic)')):
        parser.add_argument(TOPIC_FLAGS[role], metavar='TOPIC', dest=f'{role}_topic',
                            help=f'{help_text}; default: auto-detected by name and type')


def _add_simulate(commands: Any) -> None:
    """Add ``simulate``: a simulated bag and its truth file."""
    simulate = commands.add_parser(
        'simulate', help='write a bag of simulated pitches and swings, with its truth file',
        description='Write a bag of physically plausible pitches (gravity and drag; spin '
        'with --spin) and '
        'swings (a rigid bat turning about moving hands, 60-80 mph at the sweet spot), kinds '
        'cycling through barrel, end-cap and handle hits, foul-tip grazes and misses over and '
        'under. Topics are the impact_node defaults: /ball (PointStamped), /bat_pose '
        '(PoseStamped), /bat_knob and /bat_tip (PointStamped), all in one frame. The truth '
        'file OUT.truth.json (without its .mcap, .db3 or .bag suffix) is written beside the bag.')
    simulate.add_argument('out', metavar='OUT', help='output bag: NAME.mcap or NAME.db3 (a '
                          'bare ROS 2 file), NAME.bag (ROS 1), or a directory name (a ROS 2 '
                          'bag in --storage)')
    simulate.add_argument('--count', type=_count, default=12, help='pitches (default 12)')
    simulate.add_argument('--kinds', type=_kinds, default=list(KINDS),
                          help=f"comma-separated kinds, cycled (default {','.join(KINDS)})")
    simulate.add_argument('--family', choices=FAMILIES, default='plane',
                          help='swings: plane (a fixed swing plane, the default), tilted (the '
                          'plane tilting 1-3 rad/s), jerky (accelerating hands, angular jerk), '
                          'lefty, braking (the bat slowing after a contact) or rebound (a real '
                          'hit: braking, and the ball leaving the bat)')
    simulate.add_argument('--plan', type=float, metavar='HZ',
                          help="a robot arm's commanded swing on /bat_plan (nav_msgs/Path), "
                          'one plan a pitch with its poses HZ apart, logged as it is tracked: '
                          "what analyze --predict --bat-plan-topic /bat_plan and the node's "
                          'bat_plan_topic predict with (default: none)')
    simulate.add_argument('--spin', action='store_true',
                          help='spinning pitches: 1,500-2,800 rpm about any axis across the '
                          'flight, the Magnus force bending it 1-7 m/s^2 (default: no spin)')
    simulate.add_argument('--rate', type=_number(0.0, False, 'Hz', MAX_RATE_HZ), default=360.0,
                          help='tracker rate in Hz, at most 100000 (default 360)')
    simulate.add_argument('--ball-rate', type=_number(0.0, False, 'Hz', MAX_RATE_HZ),
                          default=None, help="the ball's own rate in Hz (cameras beside a bat "
                          "tracked by mocap or a robot's joints at --rate); default: --rate")
    simulate.add_argument('--jitter', type=_number(0.0, True, 's'), default=0.0002,
                          help='stamp jitter standard deviation in s (default 0.0002)')
    simulate.add_argument('--grid', type=_number(1e-9, True, 's'), default=None,
                          help='round stamps to this grid in s, e.g. 0.001 for a millisecond '
                          'mocap clock (360 Hz then steps 2 and 3 ms); default: none')
    simulate.add_argument('--noise', type=_number(0.0, True, 'm'), default=0.0,
                          help='position noise per axis in m (default 0)')
    simulate.add_argument('--marker-spread', type=_number(0.0, False, 'm'), default=None,
                          help="the bat's knob and tip markers each with their own noise, and "
                          "the pose's orientation noise of a rigid-body solve over markers "
                          'this far apart in m (a mocap rig: 0.3); default: one draw shakes '
                          'the whole bat, its knob-tip length exact')
    simulate.add_argument('--noise-on', choices=NOISE_ON, default='both',
                          help="the bodies with that noise (default both; ball: an arm's bat "
                          'from its joints beside a camera-tracked ball)')
    simulate.add_argument('--spacing', type=_number(0.0, False, 's'), default=2.0,
                          help='seconds between pitch starts; nothing is published between '
                          'pitches (default 2.0)')
    simulate.add_argument('--seed', type=_seed, default=0,
                          help='random seed, 0 to 2^64 - 1 (default 0)')
    simulate.add_argument('--storage', choices=('mcap', 'sqlite3', 'rosbag1'), default=None,
                          help='bag storage (default: from the OUT suffix; MCAP for a '
                          'directory)')
    simulate.add_argument('--frame-id', default='world', help='frame of every message '
                          "(default 'world')")
    simulate.add_argument('--bat', choices=BAT_CHOICES, default='both',
                          help='bat topics: the pose and knob/tip points (default), or one')
    simulate.add_argument('--unique', type=_count, default=None,
                          help='draw only this many pitches and repeat them (large bags fast)')
    simulate.set_defaults(run=_simulate)


def _add_analyze(commands: Any) -> None:
    """Add ``analyze``: the detector over bags, with its reports and outputs."""
    analyze = commands.add_parser(
        'analyze', help='run the detector over bags: table, JSON, CSV, plots, output bag',
        description='Run the impact detector over ROS 2 (MCAP, sqlite3) and ROS 1 bags: every '
        "sample in the bag's order, then the end of the recording. Prints one row per impact "
        'and near miss, a summary, and the comparison with the truth file beside the bag if '
        'there is one. Model: --model, else the parameter file, else c2 with look_ahead 2 and '
        'tracker_noise auto (each unless the parameter file sets it).')
    analyze.intermixed = True  # (analyze BAG1 --json o.json BAG2)
    analyze.add_argument('bags', metavar='BAG', nargs='+',
                         help='bag directory, .mcap, .db3 or ROS 1 .bag file, or a directory '
                         'of bags (each bag in it and in its subdirectories, by name)')
    analyze.add_argument('--keep-going', action='store_true',
                         help='skip a bag that cannot be analysed (one line on stderr each) and '
                         'analyse and write the others; the exit code is still 2')
    analyze.add_argument('--jobs', type=_count, default=None, metavar='N',
                         help="bags analysed (and with --plot, bags' figures drawn) at once, "
                         'each in its own process (default: the number of cores)')
    analyze.add_argument('--params', metavar='YAML', help="the node's parameter file: the "
                         'sections the node takes, as rcl applies them (/**:, /*:, '
                         '<node_name>:, wildcards; later over earlier) ros__parameters:')
    analyze.add_argument('--node-name', default=NODE_NAME,
                         help='the node whose sections of --params apply (with its namespace: '
                         'cage2/impact_node), whose namespace the relative topics of --params '
                         'take (ball: /cage2/ball), as the node expands them, and of the '
                         '--out-bag topics (default impact_node)')
    analyze.add_argument('--remap', action='append', default=[], metavar='FROM:=TO',
                         help="a remapping rule as the node's --ros-args -r takes it, repeated "
                         'as needed: the topics the node would read, and those --out-bag writes '
                         '(ball:=/mocap/ball, ~/impact:=/arm/impact), the node renamed or '
                         'moved (__node:=NAME, __ns:=/NS), a rule for one node (NODE:FROM:=TO)')
    analyze.add_argument('--model', choices=MODELS,
                         help='motion model between samples (default: --params, else c2 with '
                         'look_ahead 2 and tracker_noise auto)')
    analyze.add_argument('--ball-radius', type=_number(0.0, False, 'm'), metavar='M',
                         help='ball radius in m (default: --params, else 0.0366)')
    analyze.add_argument('--bat-radius', type=_number(0.0, False, 'm'), metavar='M',
                         help='constant bat radius in m, replacing the bat profile')
    _add_topic_flags(analyze)
    analyze.add_argument('--bat-plan-topic', metavar='TOPIC', dest='bat_plan_topic',
                         help="an arm's commanded bat trajectories (nav_msgs/Path), as the "
                              "node's bat_plan_topic: with --predict, each taken where the "
                              "samples' log times pass it (default: the --params file's; '': "
                              'none)')
    analyze.add_argument('--predict', type=_number(0.0, False, 's'), nargs='?', const=0.3,
                         default=None, metavar='SECONDS',
                         help='also predict each coming impact this far ahead (default 0.3 s, '
                         'as the node does with prediction_horizon) and score the predictions '
                         'at 200, 100, 50 and 20 ms before each impact (time error ms / point '
                         "error cm; '-' where no prediction was in force that far ahead: the "
                         'ball or bat not yet tracked, or the contact beyond the horizon)')
    analyze.add_argument('--decimate', type=_factor, nargs='+', default=[], metavar='K',
                         help='also analyse each bag at 1/K of its rate (every K-th frame of '
                         'each input, once from each of the K phases) and say how far its '
                         'impacts move from these: instant, spot and sweet-spot speed, and the '
                         'share within 1 and 2 of their 1-sigma uncertainties (a rig without '
                         'truth: what a slower one would lose); K from 2')
    analyze.add_argument('--json', metavar='FILE', help="write events and counts as JSON ('-': "
                         'to standard output, instead of the table)')
    analyze.add_argument('--csv', metavar='FILE', help="write one row per event as CSV ('-': to "
                         'standard output, instead of the table)')
    analyze.add_argument('--plot', metavar='DIR', help='write a PNG per impact and a '
                         'summary PNG per bag into DIR (created; must not exist)')
    analyze.add_argument('--out-bag', metavar='FILE', help='write an MCAP with the input '
                         'topics and the node output topics (one BAG only)')
    analyze.add_argument('--no-truth', action='store_true',
                         help='ignore a truth file beside the bag')
    analyze.add_argument('--no-progress', action='store_true', help='never show a progress bar')
    analyze.add_argument('--quiet', action='store_true', help='print nothing (outputs only)')
    analyze.set_defaults(run=_analyze)


def _add_replay(commands: Any) -> None:
    """Add ``replay``: a bag published over ROS 2 with ``/clock``."""
    replay = commands.add_parser(
        'replay', help='publish a bag over ROS 2 with /clock (like ros2 bag play --clock)',
        description='Publish every topic of a bag with its type, paced by log time, with '
        '/clock, reliable QoS and deep queues.')
    replay.add_argument('bag', metavar='BAG', help='bag directory, .mcap, .db3 or .bag file')
    replay.add_argument('--rate', type=_number(0.0, False, 'speed factor'), default=1.0,
                        help='playback speed factor (default 1)')
    replay.add_argument('--loop', action='store_true', help='restart at the end (until Ctrl-C)')
    replay.add_argument('--clock', type=_number(0.0, True, 'Hz'), default=200.0, metavar='HZ',
                        help='/clock rate in Hz of wall time; 0: no /clock (default 200)')
    replay.add_argument('--wait-for', action='append', metavar='TOPIC', default=[],
                        help='before playing, wait for a subscriber on TOPIC (repeatable)')
    replay.add_argument('--wait-timeout', type=_number(0.0, False, 's'), default=30.0,
                        metavar='S', help='longest --wait-for wait in s (default 30)')
    replay.set_defaults(run=_replay)


def _add_demo(commands: Any) -> None:
    """Add ``demo``: the live node fed a bundled bag."""
    demo = commands.add_parser(
        'demo', help='the main job: a live impact_node fed a bundled bag over DDS',
        description='Start impact_node on a private DDS domain with the bundled parameter file, '
        'replay a bundled bag into it, print each impact as it arrives, then compare with the '
        "bag's truth and with the offline analysis. Exit code 0 on success.")
    demo.add_argument('--bag', default=None, help='bag to replay (default: the bundled '
                      'bags/pitches_360hz.mcap)')
    demo.add_argument('--params', default=None, help='node parameter file (default: the '
                      'bundled config/impact_node.yaml)')
    demo.add_argument('--rate', type=_number(0.0, False, 'speed factor'), default=4.0,
                      help='replay speed factor (default 4)')
    demo.add_argument('--timeout', type=_number(0.0, False, 's'), default=30.0,
                      help='longest wait in s for the node to come up (default 30)')
    demo.add_argument('--domain', type=_domain, default=None, metavar='ID',
                      help='ROS_DOMAIN_ID to run on (0-101), so that RViz or Foxglove on '
                      'this host can watch (default: a random one)')
    demo.set_defaults(run=_demo)


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser with every subcommand."""
    parser = _Parser(
        prog=PROG, description='Find the instant a tracked bat hits a tracked ball: simulate '
        'recordings, analyse bags offline, replay them to the live node, or run the demo.')
    parser.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND',
                                     parser_class=_Command)
    for add in (_add_simulate, _add_analyze, _add_replay, _add_demo):
        add(commands)
    return parser


def _fail(message: str) -> int:
    """Print one error line and return the bad-input exit code."""
    text = ' '.join(str(message).split())
    sys.stderr.write(f'{PROG}: error: {text}\n')
    return EXIT_BAD_INPUT


def main(argv: Optional[List[str]] = None, *, end: bool = False) -> int:
    """
    Run the command line.

    :param argv: the arguments after the program name; None: ``sys.argv[1:]``.
    :param end: after ``analyze``, end the process at once unless something would be lost
        (:func:`~baseball_collision.tools.ending.end_process`: no interpreter teardown), as the
        console script does; the function then returns only when it could not.
    :returns: the exit code: 0 success, 1 a failed demo, 2 bad input, 130 interrupted (Ctrl-C),
        143 terminated (SIGTERM), 129 hung up (SIGHUP); interrupted or terminated, no partial
        output is left behind.
    """
    single_threaded_blas()
    argv = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(argv)
    args.argv = argv
    code = _run(args)
    if end and args.command == 'analyze':
        return end_process(code)
    return code


def _run(args: argparse.Namespace) -> int:
    """Run the parsed command; return its exit code (:func:`main`'s)."""
    try:
        with cleanup_on_signals():
            return args.run(args)
    except Terminated as signalled:
        sys.stderr.write(f'{PROG}: terminated by {signalled.name}; no output written\n')
        return 128 + signalled.signum
    except BaseballCollisionError as error:
        return _fail(str(error))
    except OSError as error:
        return _fail(f'{error.strerror or error}: {error.filename or ""}')
    except ModuleNotFoundError as error:
        package = (error.name or '').split('.')[0] or str(error)
        return _fail(f"{args.command} needs the Python package '{package}', which is not "
                     f'installed (pip install {PIP_NAMES.get(package, package)})')
    except KeyboardInterrupt:
        sys.stderr.write(f'{PROG}: interrupted\n')
        return EXIT_INTERRUPTED


if __name__ == '__main__':
    sys.exit(main(end=True))
