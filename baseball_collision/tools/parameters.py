"""
Node parameter files for the offline tools: read the ``impact_node``'s YAML, build the config.

No rclpy: the ROS 2 YAML the ``impact_node`` takes (``<node_name>: ros__parameters:`` and
``/**: ros__parameters:`` sections, nested keys joined by ``.``) is read with PyYAML
(:func:`load_parameters`: the sections rcl applies, ``core.detector.section_applies``), and
:func:`build_config` turns it, with command-line overrides, into a
:class:`~baseball_collision.core.detector.DetectorConfig`. :func:`output_topics` names the
node's event topics (``--out-bag`` writes them, the demo listens to them).
"""

from dataclasses import dataclass
import os
from pathlib import Path
import re
from typing import Any, Dict, Iterable, List, Mapping, Optional, Tuple, Union

from ..core.detector import (
    DetectorConfig, node_fqn, NODE_NAME, section_applies, validate_parameters)
from ..errors import CoreError, ToolError

OFFLINE_MODEL = 'c2'
"""Motion model used offline when neither a flag nor the parameter file names one."""

OFFLINE_PARAMETERS: Dict[str, Any] = {'look_ahead': 2, 'tracker_noise': -1.0}
"""The offline model's settings, each where the parameter file does not give it (and only when
the model is the offline default: a model named by a flag or the file keeps the node's
defaults): ``c2`` fitting 2 frames past each interval, with each stream's noise estimated from
its samples (auto). The most accurate offline setting measured, at 0.8 or more of ``spline``'s
``analyze`` throughput on the worst-case bag (BENCHMARKS.md, "A compiled window fit")."""

TOPIC_PARAMETERS = {'ball': 'ball_topic', 'bat_pose': 'bat_pose_topic', 'knob': 'knob_topic',
                    'tip': 'tip_topic', 'bat_plan': 'bat_plan_topic'}
"""The node's topic parameters by role."""

_TOPIC_TOKEN = re.compile(r'^(?:[A-Za-z_][A-Za-z0-9_]*|\{[A-Za-z_][A-Za-z0-9_]*\})$')


def topic_name_error(name: str) -> Optional[str]:
    """
    Return why ``name`` is not a valid ROS 2 topic name (rcl's rules), or None when it is.

    Letters, digits, ``_``, ``/``, a leading ``~`` (the node's namespace) and ``{name}``
    substitutions; no empty token (``//``), no trailing ``/``, no token starting with a digit.
    """
    if not name:
        return 'topic name must not be empty'
    if re.search(r'[^A-Za-z0-9_/~{}]', name):
        return ("topic name must not contain characters other than alphanumerics, '_', '~', "
                "'{', or '}'")
    body = name[1:] if name.startswith('~') else name
    if '~' in body or (name.startswith('~') and body and not body.startswith('/')):
        return "'~' may only begin a topic name, followed by '/'"
    if body.endswith('/'):
        return "topic name must not end with '/'"
    if '//' in body:
        return "topic name must not contain repeated '/'"
    for token in body.split('/'):
        if token and not _TOPIC_TOKEN.match(token):
            return f"topic name token '{token}' must not start with a number or hold a brace"
    return None


_SUBSTITUTION = re.compile(r'\{([^{}]*)\}')


def resolve_topic(name: str, node_name: str = NODE_NAME) -> str:
    """
    Return a topic parameter as the node expands it (rcl's rules), before any remapping.

    A relative name takes the node's namespace (``ball`` -> ``/ball`` for ``impact_node``,
    ``/cage2/ball`` for ``cage2/impact_node``); ``~`` is the node's full name (``~/bat`` ->
    ``/cage2/impact_node/bat``); ``{node}`` is its name, ``{ns}`` and ``{namespace}`` its
    namespace; an absolute name stays. The result is not checked (``{ns}/x`` in the root
    namespace gives ``//x``, which the node refuses: :func:`topic_name_error`).

    :param name: the topic as the parameter gives it.
    :param node_name: the node's name, with its namespace for a node under one
        (``cage2/impact_node``).
    :raises ToolError: an unknown substitution (``{foo}``), which the node refuses too.
    """
    fqn = node_fqn(node_name)
    namespace, _, base = fqn.rpartition('/')
    values = {'node': base, 'ns': namespace or '/', 'namespace': namespace or '/'}
    if name.startswith('~'):
        name = fqn + name[1:]
    unknown = [key for key in _SUBSTITUTION.findall(name) if key not in values]
    if unknown:
        raise ToolError(f'unknown substitution {{{unknown[0]}}} in topic name {name!r} (rcl '
                        'knows {node}, {ns} and {namespace})')
    name = _SUBSTITUTION.sub(lambda match: values[match.group(1)], name)
    return name if name.startswith('/') else f'{namespace}/{name}'


_NODE_TOKEN = re.compile(r'^[A-Za-z_][A-Za-z0-9_]*$')


@dataclass(frozen=True)
class Remapping:
    """
    The node's remapping rules (``--ros-args -r FROM:=TO``), applied as rcl applies them.

    No rclpy. ``__ns:=/NS`` moves the node to namespace NS and ``__node:=NAME`` (or
    ``__name``) renames it; every other rule renames a topic. A rule prefixed ``NODE:`` applies
    only to the node of that name (a namespace or topic rule: to the node renamed). A topic
    rule matches a topic whose expanded name (``resolve_topic``: relative names take the node's
    namespace, ``~`` is the node) is its FROM expanded the same way; the first rule of each kind
    that matches applies, its TO expanded. Wildcards and substitutions, which rcl does not take
    in a rule, are refused. Checked against rclpy's own ``resolve_topic_name``
    (``test/ros/test_parameters.py``).

    :ivar node_name: the node with its namespace after the rules (``cage2/impact_node``).
    :ivar rules: the topic rules in order: (the node they are for or '', FROM, TO).
    """

    node_name: str = NODE_NAME
    rules: Tuple[Tuple[str, str, str], ...] = ()

    @classmethod
    def parse(cls, rules: Iterable[str], node_name: str = NODE_NAME) -> 'Remapping':
        """
        Return the rules ``[NODE:]FROM:=TO`` for the node ``node_name`` (with its namespace).

        :raises ToolError: a rule without ``:=`` or with more than one, a FROM or TO that is
            not a valid name (rcl's rules: ``topic_name_error``), a namespace that is not
            absolute, a node name with more than one token, a wildcard or a substitution.
        """
        namespace, _, base = node_fqn(node_name).rpartition('/')
        given = base
        moved: Dict[str, str] = {}  # (the first __node rule for the node, each node's __ns)
        topic_rules = []
        for rule in rules:
            left, sign, right = rule.partition(':=')
            if not sign or ':=' in right:
                raise ToolError(f"remapping rule {rule!r} must read FROM:=TO (one ':=')")
            node, _, match = left.rpartition(':')
            if re.search(r'[*{}]', rule):
                raise ToolError(f'remapping rule {rule!r}: wildcards and substitutions are not '
                                'supported (rcl does not take them in a rule)')
            if node and not _NODE_TOKEN.match(node):
                raise ToolError(f"remapping rule {rule!r}: '{node}' is not a node name")
            if match == '__ns':
                if not right.startswith('/') or right != '/' and topic_name_error(right):
                    raise ToolError(f'remapping rule {rule!r}: a namespace must be absolute '
                                    '(/cage2)')
                moved.setdefault(f'namespace {node}', '' if right == '/' else right)
                continue
            if match in ('__node', '__name'):
                if not _NODE_TOKEN.match(right):
                    raise ToolError(f"remapping rule {rule!r}: '{right}' is not a node name")
                if not node or node == given:
                    moved.setdefault('base', right)
                continue
            for name in (match, right):
                problem = topic_name_error(name)
                if problem:
                    raise ToolError(f'remapping rule {rule!r}: {problem}')
            topic_rules.append((node, match, right))
        base = moved.get('base', base)  # (a namespace rule's node: the node renamed)
        namespace = next((value for key, value in moved.items()
                          if key in ('namespace ', f'namespace {base}')), namespace)
        return cls(f'{namespace}/{base}'.lstrip('/'), tuple(topic_rules))

    def topic(self, name: str) -> Tuple[str, Optional[str]]:
        """
        Return a topic as the node expands and remaps it, with the rule that renamed it.

        :returns: (the fully qualified name, the rule as ``FROM:=TO``, or None where none
            matched).
        :raises ToolError: an unknown substitution (``resolve_topic``).
        """
        expanded = resolve_topic(name, self.node_name)
        base = self.node_name.rpartition('/')[2]
        for node, match, replacement in self.rules:
            if (not node or node == base) and resolve_topic(match, self.node_name) == expanded:
                rule = f"{node + ':' if node else ''}{match}:={replacement}"
                return resolve_topic(replacement, self.node_name), rule
        return expanded, None


def _topic_problem(name: str, node_name: str) -> Optional[str]:
    """Return why the node refuses a topic parameter, as given or once expanded; None: valid."""
    problem = topic_name_error(name)
    if problem is None:
        try:
            problem = topic_name_error(resolve_topic(name, node_name))
        except ToolError as error:
            problem = str(error)
    return problem


def _mixed_sequences(prefix: str, values: Mapping[str, Any]) -> Optional[str]:
    """Return the first parameter whose list mixes value types (rcl refuses it), or None."""
    for key, value in values.items():
        if isinstance(value, Mapping):
            found = _mixed_sequences(f'{prefix}{key}.', value)
            if found:
                return found
        elif isinstance(value, list) and len({type(item) for item in value}) > 1:
            kinds = ', '.join(sorted({type(item).__name__ for item in value}))
            return (f"parameter '{prefix}{key}' mixes value types in one list ({kinds}); "
                    'the node refuses the file (write 0.0, not 0, among decimals)')
    return None


def _flatten(prefix: str, values: Mapping[str, Any], into: Dict[str, Any]) -> None:
    """Flatten nested parameter mappings into ``into`` with ``.``-joined names."""
    for key, value in values.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping):
            _flatten(f'{name}.', value, into)
        else:
            into[name] = value


MAX_DEPTH = 32
"""Deepest nesting of a parameter file (ROS 2 parameter files need 4 or 5 levels)."""

MAX_LIST = 4096
"""Most values in one list of a parameter file (the longest parameter takes 512)."""


def _check_events(events: Iterable[Any], path: Path) -> None:
    """
    Refuse aliases, nesting deeper than MAX_DEPTH and lists longer than MAX_LIST, as parsed.

    Reads the YAML events (no recursion, no alias expansion), stopping at the first problem,
    so neither an alias bomb nor a million-value list is ever built.

    :raises ToolError: one line naming the problem and its line.
    """
    import yaml

    lists: List[int] = []  # values so far in each open list, -1 for an open mapping
    for event in events:
        line = event.start_mark.line + 1
        if isinstance(event, yaml.AliasEvent):
            raise ToolError(f'parameter file {path}: YAML aliases are not allowed (line {line})')
        if isinstance(event, (yaml.ScalarEvent, yaml.CollectionStartEvent)) and lists \
                and lists[-1] >= 0:
            lists[-1] += 1
            if lists[-1] > MAX_LIST:
                raise ToolError(f'parameter file {path}: a list longer than {MAX_LIST} values '
                                f'(line {line})')
        if isinstance(event, yaml.CollectionStartEvent):
            lists.append(0 if isinstance(event, yaml.SequenceStartEvent) else -1)
            if len(lists) > MAX_DEPTH:
                raise ToolError(f'parameter file {path}: nested deeper than {MAX_DEPTH} levels '
                                f'(line {line})')
        elif isinstance(event, yaml.CollectionEndEvent):
            lists.pop()


def _sections(text: str) -> Optional[List[Tuple[str, Any]]]:
    """
    Return a params file's top-level sections as (key, value) pairs in file order.

    A key given twice is one section at its first place, its values merged (the later wins),
    as rcl keeps it (PyYAML keeps only the later value). None: the document is no mapping.
    """
    import yaml

    root = yaml.compose(text, Loader=getattr(yaml, 'CSafeLoader', yaml.SafeLoader))
    if not isinstance(root, yaml.MappingNode):
        return None
    constructor = yaml.constructor.SafeConstructor()
    sections: Dict[str, List[Any]] = {}
    for key, value in root.value:
        sections.setdefault(str(constructor.construct_document(key)), []).append(
            constructor.construct_document(value))
    return list(sections.items())


def load_parameters(path: os.PathLike, node_name: str = NODE_NAME) -> Dict[str, Any]:
    """
    Read the parameters a ROS 2 node would take from a ``--params-file`` YAML, checked as it does.

    The sections rcl applies to the node (:func:`section_applies`: ``/**``, ``/*``,
    ``<node_name>``, ``/<ns>/<node_name>``, wildcards such as ``/**/<node_name>``), with rcl's
    precedence: in the file's order, a later section over an earlier one, whichever is more
    specific (a key given twice counts at its first place, its values merged). Each section's
    ``ros__parameters`` mapping is flattened: nested mappings become ``outer.inner`` names. The
    values are checked with the node's rules (``core.detector.validate_parameters``): a file
    the node would refuse is refused with the same message: also a list mixing value types
    (``[0, 0.5]``: rcl's parser refuses it) and a topic name ROS refuses, as given or once
    expanded for ``node_name`` (:func:`resolve_topic`: ``{ns}/x`` in the root namespace). YAML
    aliases, nesting deeper than 32 levels and lists longer than 4096 values are refused as
    the file is parsed.

    :param path: the YAML file.
    :param node_name: the node's name, with its namespace for a node under one
        (``cage2/impact_node``).
    :returns: ``{parameter name: value}`` as the file gives them (names the node does not know
        included).
    :raises ToolError: the file is missing or not YAML, has aliases, deep nesting or a long
        list, has no section for the node, a section without a ``ros__parameters`` mapping, a
        list mixing value types, an invalid topic name, or a value the node refuses.
    """
    import yaml  # PyYAML, as ROS 2's own tools use; imported here so analyze starts fast

    path = Path(path)
    try:
        text = path.read_text()
        # checked lazily event by event (stops at the first problem), then composed by libyaml
        _check_events(yaml.parse(text, Loader=yaml.SafeLoader), path)
        sections = _sections(text)
    except OSError as error:
        raise ToolError(f'cannot read parameter file {path}: {error.strerror}') from error
    except yaml.YAMLError as error:
        first = str(error).strip().splitlines()[0] if str(error).strip() else 'invalid'
        raise ToolError(f'parameter file {path} is not valid YAML: {first}') from error
    if sections is None:
        raise ToolError(f'parameter file {path} is not a mapping of node names')
    fqn = node_fqn(node_name)
    applied = [(key, values) for key, values in sections if section_applies(key, fqn)]
    if not applied:
        found = ', '.join(key for key, _ in sections) or 'nothing'
        raise ToolError(
            f"parameter file {path} has no section for node '{fqn}' (found: {found}): name "
            "the section '/**' or the node's name")
    parameters: Dict[str, Any] = {}
    for key, values in applied:
        for section in values:
            inner = section.get('ros__parameters') if isinstance(section, Mapping) else None
            if not isinstance(inner, Mapping):
                raise ToolError(
                    f"parameter file {path}: section '{key}' has no ros__parameters mapping")
            mixed = _mixed_sequences('', inner)
            if mixed:
                raise ToolError(f'parameter file {path}: {mixed}')
            _flatten('', inner, parameters)
    try:
        validate_parameters(parameters)
    except CoreError as error:
        raise ToolError(f'parameter file {path}: {error}') from error
    for name in TOPIC_PARAMETERS.values():
        problem = _topic_problem(parameters[name], node_name) if parameters.get(name) else None
        if problem is not None:
            raise ToolError(f"parameter file {path}: parameter '{name}' = "
                            f'{parameters[name]!r}: Invalid topic name: {problem}')
    return parameters


def build_config(parameters: Mapping[str, Any], *, bat_input: str,
                 model: Optional[str] = None, ball_radius: Optional[float] = None,
                 bat_radius: Optional[float] = None,
                 prediction_horizon: Optional[float] = None) -> DetectorConfig:
    """
    Build the detector configuration: flags over the parameter file over offline defaults.

    :param parameters: flat node parameters (e.g. from :func:`load_parameters`; may be empty).
    :param bat_input: ``'pose'`` or ``'points'``, as the bag's selected topics give it.
    :param model: motion model flag; None: the file's ``model``, else :data:`OFFLINE_MODEL`
        with :data:`OFFLINE_PARAMETERS` where the file does not set them.
    :param ball_radius: ball radius flag (m); None: the file's, else the detector default.
    :param bat_radius: constant bat radius flag (m), replacing the profile; None: the file's.
    :param prediction_horizon: ``--predict`` horizon (s); None: no prediction, whatever the
        file says (its ``prediction_horizon`` is the node's; ``prediction_period`` and the
        other prediction parameters come from the file or the table, as the node's do).
    :returns: the configuration.
    :raises ToolError: a value the node would refuse (the message names the parameter).
    """
    named = model or parameters.get('model')
    flags = {'model': named or OFFLINE_MODEL, 'bat_input': bat_input,
             'ball_radius': ball_radius, 'bat_radius': bat_radius,
             'prediction_horizon': 0.0 if prediction_horizon is None else prediction_horizon}
    values = dict({} if named else OFFLINE_PARAMETERS, **parameters)
    values.update((name, v) for name, v in flags.items() if v is not None)
    try:
        return DetectorConfig.from_parameters(values)
    except CoreError as error:
        raise ToolError(f'bad detector setting: {error}') from error


def output_topics(node: Union[str, Remapping] = NODE_NAME) -> Dict[str, str]:
    """
    Return the node's output topics: ``{'impact': '/<node>/impact', ...}``.

    ``impact``, ``impact_velocity``, ``near_miss``, ``predicted_impact``, ``impact_report``,
    ``markers`` (``~/`` topics of the node) and ``diagnostics`` (``/diagnostics``), for the
    node named (with its namespace), or as a ``Remapping``'s node has them.
    """
    remapping = Remapping(node) if isinstance(node, str) else node
    names = ('impact', 'impact_velocity', 'near_miss', 'predicted_impact', 'impact_report',
             'markers')
    return {**{name: remapping.topic(f'~/{name}')[0] for name in names},
            'diagnostics': remapping.topic('/diagnostics')[0]}
