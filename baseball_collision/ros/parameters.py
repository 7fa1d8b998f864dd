"""
The node's parameters: declared from the core's table, checked with the core's rules.

Every parameter, its type, default, range and whether it may change at runtime is in
``core.detector.PARAMETERS``; values are checked by ``core.detector.validate_parameters``
(the same function ``analyze --params`` uses), so the node and the offline tools refuse the
same values with the same one-line messages. ROS adds one check of its own: topic names.

At start-up each parameter is declared with its descriptor built from the table (type, range,
read-only); a value rclpy would refuse is declared loosely instead, so that the core's check,
not rclpy's, says why (:func:`declare`). At runtime :func:`check_change` validates a change
(a read-only parameter refused with the reason) before rclpy sees it.
A ``--params-file`` none of whose sections applies to the node (rcl's rules,
``core.detector.section_applies``, which ``analyze --params`` reads a file by) is warned
about at start-up (:func:`params_file_warnings`).
"""

from dataclasses import dataclass
import math
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import (
    InvalidParameterTypeException, InvalidParameterValueException, InvalidTopicNameException)
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.validate_topic_name import validate_topic_name

from ..core.detector import (
    DetectorConfig, Kind, PARAMETERS, ParameterSpec, section_applies, SPECS, unknown_parameters,
    validate_parameters)
from ..errors import CoreError, RosError

ROS_TYPES = {Kind.BOOL: Parameter.Type.BOOL, Kind.INTEGER: Parameter.Type.INTEGER,
             Kind.DOUBLE: Parameter.Type.DOUBLE, Kind.STRING: Parameter.Type.STRING,
             Kind.DOUBLE_ARRAY: Parameter.Type.DOUBLE_ARRAY}
"""The rclpy parameter type of each kind in the table."""


def descriptor(spec: ParameterSpec) -> ParameterDescriptor:
    """Return a new ParameterDescriptor for a parameter of the table (rclpy mutates it)."""
    constraints = [f'unit: {spec.unit}'] if spec.unit else []
    if spec.choices:
        constraints.append('one of: ' + ', '.join(spec.choices))
    if spec.bounds is not None and (spec.bounds.low_open or spec.bounds.high_open):
        constraints.append(f'in {spec.bounds}')
    if spec.read_only:
        constraints.append(f'read-only: {spec.read_only}; restart the node to change it')
    result = ParameterDescriptor(
        name=spec.name, type=ROS_TYPES[spec.kind].value, description=spec.doc,
        additional_constraints='; '.join(constraints), read_only=bool(spec.read_only))
    if spec.bounds is not None and spec.kind == Kind.DOUBLE:
        result.floating_point_range = [FloatingPointRange(
            from_value=float(spec.bounds.low), to_value=float(spec.bounds.high), step=0.0)]
    if spec.bounds is not None and spec.kind == Kind.INTEGER:
        result.integer_range = [IntegerRange(
            from_value=int(spec.bounds.low), to_value=int(spec.bounds.high), step=1)]
    return result


@dataclass(frozen=True)
class Settings:
    """
    The node's checked parameters.

    :ivar values: every parameter's value by name (doubles as float, arrays as lists).
    :ivar detector: the detector configuration built from them.
    """

    values: Mapping[str, Any]
    detector: DetectorConfig

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> 'Settings':
        """
        Check parameter values as the node does and build the detector configuration.

        :param values: parameter values by name (missing: default; ``None``: an unset array).
        :raises RosError: a value the node cannot run with: one line naming the parameter.
        """
        try:
            checked = validate_parameters(values)
            detector = DetectorConfig.from_parameters(checked)
        except CoreError as error:
            raise RosError(str(error)) from error
        for name, value in checked.items():
            if name.endswith('_topic') and (value or name != 'bat_plan_topic'):
                try:
                    validate_topic_name(value)
                except InvalidTopicNameException as error:
                    first = str(error).splitlines()[0].rstrip(':')
                    raise RosError(f"parameter '{name}' = {value!r}: {first}") from error
        return cls(values=checked, detector=detector)

    def __getitem__(self, name: str) -> Any:
        """Return the value of a parameter by name."""
        return self.values[name]


def declare(node: Node) -> Settings:
    """
    Declare every parameter of the table on ``node``; return the checked settings.

    Each parameter is declared with its final descriptor (type, range, read-only). A given
    value rclpy refuses for that descriptor (wrong type, out of range), and an array without a
    default (rclpy cannot declare an empty array by value), are declared loosely instead
    (dynamically typed), so that the value reaches the core's check and is refused with the
    core's message, or taken (an int for a double, converted); the final descriptor is then
    set with the checked value.

    :raises RosError: a given value (``--params-file``, ``-p``, overrides) the node cannot run
        with: one line naming the parameter.
    """
    given, loose = {}, []
    for spec in PARAMETERS:
        if spec.default != ():
            try:
                given[spec.name] = node.declare_parameter(
                    spec.name, spec.default, descriptor(spec)).value
                continue
            except (InvalidParameterTypeException, InvalidParameterValueException):
                pass  # not declared: the core's check below says why
        given[spec.name] = node.declare_parameter(spec.name, spec.default, ParameterDescriptor(
            description=spec.doc, dynamic_typing=True)).value
        loose.append(spec)
    settings = Settings.from_values(given)
    for spec in loose:
        value = Parameter(spec.name, ROS_TYPES[spec.kind], settings[spec.name])
        node.set_descriptor(spec.name, descriptor(spec), value.get_parameter_value())
    return settings


def check_change(settings: Settings,
                 parameters: List[Parameter]) -> Tuple[Settings, List[Parameter]]:
    """
    Check a runtime change of parameters as one.

    :param settings: the node's settings now.
    :param parameters: the change (parameters not in the table pass untouched).
    :returns: the settings after the change, and the parameters to set (converted: an int
        given for a double becomes a float).
    :raises RosError: a read-only parameter (why, and to restart), or a value the node cannot
        run with: one line naming the parameter.
    """
    values = dict(settings.values)
    for parameter in parameters:
        spec = SPECS.get(parameter.name)
        if spec is not None and spec.read_only:
            raise RosError(f"parameter '{spec.name}' is read-only: {spec.read_only}; restart "
                           'the node with the new value')
        if spec is not None:
            values[spec.name] = parameter.value
    changed = Settings.from_values(values)
    return changed, [Parameter(p.name, ROS_TYPES[SPECS[p.name].kind], changed[p.name])
                     if p.name in SPECS else p for p in parameters]


def start_warnings(node: Node, config: DetectorConfig) -> List[str]:
    """
    Return what to warn about at start-up.

    Overrides (params file, ``-p``) that name no parameter of ``node`` (typos), and pose
    offsets that disagree with the bat profile on the bat length.
    """
    warnings = []
    # rclpy has no public accessor for the overrides given on the command line / params file
    overrides: Dict[str, Any] = getattr(node, '_parameter_overrides', {}) or {}
    unknown = unknown_parameters(
        [name for name in overrides if not node.has_parameter(name)], node.get_name())
    if unknown is not None:
        warnings.append(unknown)
    if config.bat_input == 'pose':
        length = math.dist(config.geometry.knob_offset, config.geometry.tip_offset)
        if abs(length - config.profile.length) > 0.01:
            warnings.append(
                f'the knob-tip distance |tip_offset - knob_offset| = {length:.4f} m but the '
                f'bat profile is {config.profile.length:.4f} m long: the profile is stretched '
                'to knob-tip')
    return warnings


def params_files(args: Sequence[str]) -> List[str]:
    """Return the ``--params-file`` paths of a command line's ROS arguments, in order."""
    files, ros, after = [], False, False
    for word in args:
        if after:
            files.append(word)
            after = False
        elif word == '--ros-args':
            ros = True
        elif word == '--':
            ros = False
        elif ros and word == '--params-file':
            after = True
    return files


def params_file_warnings(args: Sequence[str], node_fqn: str) -> List[str]:
    """
    Return a warning for each ``--params-file`` of ``args`` with no section for the node.

    rcl applies only the sections naming the node (or matching it by wildcard) and says
    nothing about a file whose sections all name other nodes (``my_node:`` after a rename, a
    section copied from another package): the node would run on its defaults unawares.
    ``analyze --params`` refuses such a file; the node warns and runs (the file may hold other
    nodes' sections on purpose, with this node's parameters given elsewhere).

    :param args: the node's command line (``sys.argv`` or ``main``'s ``args``).
    :param node_fqn: the node's fully qualified name (``/impact_node``, ``/cage2/impact_node``).
    """
    import yaml  # PyYAML (python3-yaml), as ROS 2's own tools use; only at start-up

    warnings = []
    for path in params_files(args):
        try:
            with open(path) as file:
                document: Optional[Any] = yaml.safe_load(file)
        except (OSError, yaml.YAMLError):
            continue  # rcl read it (or refused to start): nothing to add
        if not isinstance(document, Mapping):
            continue
        if not any(section_applies(str(key), node_fqn) for key in document):
            found = ', '.join(str(key) for key in document) or 'nothing'
            warnings.append(
                f"parameter file {path} has no section for node '{node_fqn}' (found: {found}): "
                "none of its parameters apply; name the section '/**' or the node's name")
    return warnings
