"""
The node's parameters: declared from the core's table, and refused exactly as analyze refuses.

For each bad value the same one-line message comes from the core's ``validate_parameters``,
from ``impact_node`` given it in a params file (start-up), from ``impact_node`` asked to take it
at runtime (parameter service), and from ``analyze --params`` reading the same file.
"""

from pathlib import Path
import re
from typing import Any, Callable

from baseball_collision.core.detector import (
    Kind, PARAMETERS, section_applies, SPECS, unknown_parameters, validate_parameters)
from baseball_collision.errors import CoreError, RosError, ToolError
from baseball_collision.ros.node import ImpactNode
from baseball_collision.ros.parameters import params_file_warnings, params_files, start_warnings
from baseball_collision.tools.parameters import load_parameters, Remapping
import pytest
from rcl_interfaces.msg import ParameterType
import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from support import REPO_ROOT
from support.harness import Harness

pytestmark = pytest.mark.ros

BAD = [  # (YAML value text, the value) of parameters that may change at runtime
    ('max_gap', '0.0', 0.0),  # the detector needs > 0 (the node used to take it)
    ('max_gap', '-1', -1),  # an int for a double, out of range
    ('ball_radius', 'true', True),  # a bool is no radius (analyze used to take it as 1 m)
    ('ball_radius', '0.75', 0.75),
    ('near_miss_threshold', '"far"', 'far'),
    ('velocity_degree', '7', 7),
    ('velocity_degree', '2.0', 2.0),  # a double for an integer
    ('up_axis', '[0.0, 0.0, 0.0]', [0.0, 0.0, 0.0]),
    ('stale_timeout', '0.0', 0.0),
    ('publish_markers', '1', 1),
]
BAD_AT_START = BAD + [  # read-only ones: refused at start-up only
    ('model', 'cubic', 'cubic'),
    ('qos', 'best_effort', 'best_effort'),
    ('qos_depth', '0', 0),
    ('bat_profile', '[0.1, 0.02, 0.3]', [0.1, 0.02, 0.3]),
    ('bat_axis', 'w', 'w'),
    ('diagnostics_period', '0.01', 0.01),
]


def core_message(name: str, value: Any) -> str:
    """Return the core's refusal of one value."""
    with pytest.raises(CoreError) as caught:
        validate_parameters({name: value})
    return str(caught.value)


@pytest.fixture
def context(monkeypatch: pytest.MonkeyPatch) -> Callable[..., rclpy.Context]:
    """Make rclpy contexts (discovery off) with a command line; shut them down after."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    made = []

    def make(*args: str) -> rclpy.Context:
        made.append(rclpy.Context())
        rclpy.init(context=made[-1], args=['--ros-args', *args])
        return made[-1]
    yield make
    for each in made:
        rclpy.shutdown(context=each)


@pytest.mark.parametrize('name, text, value', BAD_AT_START,
                         ids=[f'{name}={text}' for name, text, _ in BAD_AT_START])
def test_node_and_analyze_refuse_a_file_with_the_same_message(
        tmp_path: Path, context: Callable[..., rclpy.Context], name: str, text: str,
        value: Any) -> None:
    """A params file with one bad value: the node and analyze give the core's one line."""
    expected = core_message(name, value)
    assert '\n' not in expected and f"'{name}'" in expected
    params = tmp_path / 'bad.yaml'
    params.write_text(f'impact_node:\n  ros__parameters:\n    {name}: {text}\n')
    with pytest.raises(RosError) as node_refusal:
        ImpactNode(context=context('--params-file', str(params)))
    assert str(node_refusal.value) == expected
    with pytest.raises(ToolError) as analyze_refusal:
        load_parameters(params)
    assert str(analyze_refusal.value) == f'parameter file {params}: {expected}'


def test_node_and_analyze_name_unknown_parameters_alike(
        tmp_path: Path, context: Callable[..., rclpy.Context]) -> None:
    """Typos in a params file: the node's start-up warning is the one analyze prints."""
    params = tmp_path / 'typos.yaml'
    params.write_text('impact_node:\n  ros__parameters:\n    modle: linear\n'
                      '    use_sim_time: false\n    qos_overrides./ball.subscription.depth: 5\n')
    node = ImpactNode(context=context('--params-file', str(params)))
    try:
        warning = unknown_parameters(load_parameters(params))
        assert warning == ('ignoring unknown parameter(s) modle (did you mean model?): not '
                           'parameters of impact_node (see config/impact_node.yaml)')
        assert start_warnings(node, node.detector.config) == [warning]
    finally:
        node.destroy_node()


SECTIONS = ['/**', '**', 'impact_node', '/impact_node', '/**/impact_node', '/*', '/*/impact_node',
            'cage2/impact_node', '/cage2/impact_node', '/cage2/*', '/cage2/**', '/impact_node/**',
            'other_node', '/cage2/other_node']


@pytest.mark.parametrize('namespace', ['/', '/cage2'])
def test_a_section_applies_where_rcl_applies_it(
        tmp_path: Path, context: Callable[..., rclpy.Context], namespace: str) -> None:
    """section_applies agrees with rcl on every key form (wildcards, relative, namespaced)."""
    for number, key in enumerate(SECTIONS):
        params = tmp_path / f'{number}.yaml'
        params.write_text(f'"{key}":\n  ros__parameters:\n    probe: 5\n')
        ros = context('--params-file', str(params))
        node = Node('impact_node', namespace=namespace, context=ros)
        try:
            applied = node.declare_parameter('probe', 0).value == 5
            assert section_applies(key, node.get_fully_qualified_name()) == applied, key
        finally:
            node.destroy_node()


FILES = {  # params files whose sections rcl applies or not, several setting one parameter
    'wildcards': ['/**: {max_gap: 0.061}', '/*: {max_gap: 0.062, rearm_distance: 0.21}',
                  '/**/impact_node: {near_miss_threshold: 0.16}'],
    'the named section first': ['impact_node: {max_gap: 0.063, ball_radius: 0.037}',
                                '/**: {max_gap: 0.064}'],
    'the named section last': ['/**: {max_gap: 0.064, ball_radius: 0.038}',
                               'impact_node: {max_gap: 0.063}'],
    'relative, absolute and wildcard': ['/impact_node: {max_gap: 0.065}',
                                        'impact_node: {rearm_distance: 0.22}',
                                        '/impact_node/**: {max_gap: 0.066}'],
    'another node and another namespace': ['other_node: {max_gap: 0.07}',
                                           '/cage2/impact_node: {max_gap: 0.071}',
                                           '/**: {rearm_distance: 0.23}',
                                           '/cage2/*: {ball_radius: 0.039}'],
    'a key given twice': ['/*: {max_gap: 0.072}', 'impact_node: {max_gap: 0.073}',
                          '/*: {max_gap: 0.074, rearm_distance: 0.24}'],
}
"""Each section as ``key: {parameter: value}``, under ``ros__parameters``, in file order."""


@pytest.mark.parametrize('namespace', ['/', '/cage2'])
@pytest.mark.parametrize('name', list(FILES))
def test_analyze_reads_the_parameters_the_node_takes(
        tmp_path: Path, context: Callable[..., rclpy.Context], name: str,
        namespace: str) -> None:
    """
    The parameters ``analyze --params`` reads are the node's: rcl's sections and precedence.

    rcl applies every section matching the node in the file's order, a later one over an
    earlier whatever their specificity (a key given twice counts at its first place); analyze
    read '/**' first and then every key ending in the node's name ('/cage2/impact_node' for
    '/impact_node' too), and knew neither '/*' nor the file's order.
    """
    params = tmp_path / 'p.yaml'
    sections = [section.split(': ', 1) for section in FILES[name]]
    params.write_text(''.join(f'"{key}":\n  ros__parameters: {values}\n'
                              for key, values in sections))
    node = ImpactNode(namespace=namespace, context=context('--params-file', str(params)))
    try:
        fqn = node.get_fully_qualified_name()
        try:
            read = load_parameters(params, fqn)
        except ToolError as error:  # no section applies: the node runs on its defaults
            assert 'has no section for node' in str(error)
            read = {}
        expected = validate_parameters(read)  # (every parameter: the file's, else default)
        for spec in PARAMETERS:
            value = node.get_parameter(spec.name).value
            assert _plain(value) == _plain(expected[spec.name]), (spec.name, fqn)
        assert any(value != SPECS[key].default for key, value in read.items()) or not read
    finally:
        node.destroy_node()


def _plain(value: Any) -> Any:
    """Return a parameter's value with an array (rclpy's ``array('d')``, a tuple) as a list."""
    return value if isinstance(value, (str, bool, int, float)) or value is None else list(value)


def test_a_params_file_for_another_node_is_named(tmp_path: Path) -> None:
    """A --params-file none of whose sections is the node's gets a warning naming them."""
    other = tmp_path / 'other.yaml'
    other.write_text('my_node:\n  ros__parameters:\n    model: linear\n')
    shipped = str(REPO_ROOT / 'config' / 'impact_node.yaml')
    args = ['impact_node', '--ros-args', '--params-file', str(other), '-p', 'x:=1', '--',
            '--params-file', 'not/a/ros/argument.yaml', '--ros-args', '--params-file', shipped]
    assert params_files(args) == [str(other), shipped]
    warning, = params_file_warnings(args, '/impact_node')
    assert warning == (f"parameter file {other} has no section for node '/impact_node' (found: "
                       "my_node): none of its parameters apply; name the section '/**' or the "
                       "node's name")
    named = tmp_path / 'named.yaml'
    named.write_text('impact_node:\n  ros__parameters:\n    model: linear\n')
    assert params_file_warnings(['--ros-args', '--params-file', str(named)], '/impact_node') == []
    assert len(params_file_warnings(['--ros-args', '--params-file', str(named)],
                                    '/cage2/impact_node')) == 1
    assert params_file_warnings(['--ros-args', '--params-file', str(tmp_path / 'gone.yaml')],
                                '/impact_node') == []  # rcl refuses it before the node starts


@pytest.mark.parametrize('name, text, value', BAD, ids=[f'{n}={t}' for n, t, _ in BAD])
def test_runtime_refusal_gives_the_start_up_message(
        harness: Callable[..., Harness], name: str, text: str, value: Any) -> None:
    """set_parameters with the same bad value: refused, with the reason given at start-up."""
    h = harness().start()
    before = h.node.get_parameter(name).value
    result = h.set_parameters(**{name: value})[0]
    assert not result.successful
    assert result.reason == core_message(name, value)
    assert h.node.get_parameter(name).value == before


def test_read_only_refusal_says_why_and_to_restart(harness: Callable[..., Harness]) -> None:
    """A read-only parameter: refused naming it, the table's reason and the restart."""
    h = harness().start()
    for spec in [SPECS['ball_topic'], SPECS['model'], SPECS['marker_rate']]:
        result = h.set_parameters(**{spec.name: spec.default})[0]
        assert not result.successful
        assert result.reason == (f"parameter '{spec.name}' is read-only: {spec.read_only}; "
                                 'restart the node with the new value')


def test_an_unknown_parameter_at_runtime_is_refused_by_name(
        harness: Callable[..., Harness]) -> None:
    """A typo set at runtime: refused naming it and the nearest parameter (rclpy named none)."""
    h = harness().start()
    result = h.set_parameters(modle='linear')[0]
    assert not result.successful
    assert result.reason == ('unknown parameter(s) modle (did you mean model?): not parameters '
                             'of impact_node (see config/impact_node.yaml)')
    assert h.node.get_parameter('model').value == 'c2'
    assert h.set_parameters(use_sim_time=False)[0].successful  # rclpy's own are parameters
    assert SPECS['model'].read_only.startswith('the motion model')


def test_descriptors_come_from_the_table(context: Callable[..., rclpy.Context]) -> None:
    """Every parameter declared with the table's type, range, read-only flag and doc."""
    node = ImpactNode(context=context())
    try:
        types = {Kind.BOOL: ParameterType.PARAMETER_BOOL,
                 Kind.INTEGER: ParameterType.PARAMETER_INTEGER,
                 Kind.DOUBLE: ParameterType.PARAMETER_DOUBLE,
                 Kind.STRING: ParameterType.PARAMETER_STRING,
                 Kind.DOUBLE_ARRAY: ParameterType.PARAMETER_DOUBLE_ARRAY}
        for spec in PARAMETERS:
            described = node.describe_parameter(spec.name)
            assert described.type == types[spec.kind], spec.name
            assert described.read_only == bool(spec.read_only), spec.name
            assert described.description == spec.doc
            assert node.get_parameter(spec.name).type_ == Parameter.Type(types[spec.kind])
            ranges = list(described.floating_point_range) + list(described.integer_range)
            if spec.bounds is None:
                assert not ranges, spec.name
            else:
                assert (ranges[0].from_value, ranges[0].to_value) == (
                    spec.bounds.low, spec.bounds.high), spec.name
            if spec.bounds is not None and spec.bounds.low_open:
                assert f'in {spec.bounds}' in described.additional_constraints
            for choice in spec.choices:
                assert choice in described.additional_constraints
    finally:
        node.destroy_node()


def test_an_int_for_a_double_is_taken_at_start_and_at_runtime(
        tmp_path: Path, harness: Callable[..., Harness]) -> None:
    """``max_gap: 1`` in a file and ``max_gap:=2`` at runtime: doubles, in the detector too."""
    params = tmp_path / 'ints.yaml'
    params.write_text('impact_node:\n  ros__parameters:\n    max_gap: 1\n    up_axis: [0, 2, 0]\n')
    h = harness(args=['--params-file', str(params)]).start()
    assert h.node.get_parameter('max_gap').value == 1.0
    assert h.node.get_parameter('max_gap').type_ == Parameter.Type.DOUBLE
    assert list(h.node.get_parameter('up_axis').value) == [0.0, 2.0, 0.0]
    assert h.node.detector.config.up_axis == (0.0, 1.0, 0.0)
    assert h.set_parameters(max_gap=2)[0].successful
    assert h.node.get_parameter('max_gap').type_ == Parameter.Type.DOUBLE
    assert h.node.detector.config.max_gap == 2.0
    assert load_parameters(params)['max_gap'] == 1


REMAPS = [
    [], ['ball:=/mocap/ball'], ['__ns:=/cage2'], ['__ns:=/cage2', 'ball:=mocap/ball'],
    ['impact_node:ball:=/a', 'ball:=/b'], ['other:ball:=/a', 'ball:=/b'],
    ['__node:=arm', 'arm:ball:=/a'], ['__node:=arm', 'impact_node:ball:=/a'],
    ['impact_node:__node:=arm', 'arm:__ns:=/x'],
    ['impact_node:__node:=arm', 'impact_node:__ns:=/x'],
    ['__ns:=/a', '__ns:=/b'], ['__node:=a', '__name:=b'], ['__ns:=/'],
    ['~/impact:=/arm/impact', '/impact_node/near_miss:=near'], ['/ball:=/x'],
    ['~/impact:=~/hit'], ['__ns:=/a/b', 'bat_pose:=~/pose'], ['ball:=/x', 'ball:=/y'],
]
"""Remapping rules (``--ros-args -r``), each list in order."""


@pytest.mark.parametrize('namespace', ['/', '/cage2'])
def test_analyze_remaps_as_rcl_remaps(context: Callable[..., rclpy.Context],
                                      namespace: str) -> None:
    """
    ``analyze --remap``'s node and topics are the node's under the same rules: rclpy's own.

    The node's full name (``__node``, ``__ns``; a rule for one node compared with its name, the
    namespace's with the node renamed), and each topic as ``resolve_topic_name`` expands and
    remaps it: the first matching rule, relative names and ``~`` in the node's namespace.
    """
    for rules in REMAPS:
        node = Node('impact_node', namespace=namespace,
                    context=context(*[a for rule in rules for a in ('-r', rule)]))
        try:
            ours = Remapping.parse(rules, f"{namespace.strip('/')}/impact_node")
            assert '/' + ours.node_name == node.get_fully_qualified_name(), rules
            for name in ('ball', '/ball', 'bat_pose', '~/impact', '~/near_miss', '/diagnostics',
                         'mocap/ball', '~'):
                assert ours.topic(name)[0] == node.resolve_topic_name(name), (rules, name)
        finally:
            node.destroy_node()


@pytest.mark.parametrize('rule', ['ball', 'ball:=', ':=/x', 'ball:=1x', 'ball:=/x/',
                                  '__ns:=cage2', '__node:=a/b', 'ball:=/x:=/y', 'a b:=/x',
                                  'ball:={node}', '**:=/x'])
def test_a_rule_rcl_refuses_is_refused(rule: str) -> None:
    """What rcl cannot parse, ``analyze --remap`` refuses, naming the rule."""
    with pytest.raises(rclpy_implementation.RCLError, match='remap rule'):
        rclpy.init(context=rclpy.Context(), args=['--ros-args', '-r', rule])
    with pytest.raises(ToolError, match=re.escape(repr(rule))):
        Remapping.parse([rule])
