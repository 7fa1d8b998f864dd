"""
Launch ``impact_node`` with its parameters file from the package's share directory.

    ros2 launch baseball_collision impact_node.launch.py
    ros2 launch baseball_collision impact_node.launch.py \
        params_file:=/path/to/my_params.yaml use_sim_time:=true namespace:=cage2 \
        log_level:=debug remappings:=ball:=/mocap/ball,bat_pose:=/mocap/bat

``config/impact_node_points.yaml`` (installed beside the default) is the knob + tip example.
Both files name their section ``/**``, so they apply under any ``namespace``.
``remappings`` is a comma-separated list of ``FROM:=TO`` (topic or service names). Write
``FROM`` as the node names it: a relative name (``ball``) is expanded in the node's namespace
and matches ``/cage2/ball``; an absolute ``/ball`` matches only a node in the root namespace.
"""

from typing import List, Tuple

from launch import LaunchContext, LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

PACKAGE = 'baseball_collision'

ARGUMENTS = (  # name, default, description (params_file's default is the share's YAML)
    ('params_file', None, 'YAML file with the impact_node parameters'),
    ('use_sim_time', 'false', 'Follow /clock (bag replay) instead of the system clock'),
    ('namespace', '', 'Namespace of the node (its ~/ topics and relative topic names)'),
    ('log_level', 'info', 'Log level: debug, info, warn, error or fatal'),
    ('remappings', '', 'Comma-separated FROM:=TO remappings, e.g. ball:=/mocap/ball'),
)


def parse_remappings(text: str) -> List[Tuple[str, str]]:
    """
    Return ``FROM:=TO[,FROM:=TO...]`` as pairs (blanks around items ignored).

    :raises ValueError: an item without ``:=`` or with an empty side.
    """
    pairs = []
    for item in (part.strip() for part in text.split(',')):
        if not item:
            continue
        source, separator, target = item.partition(':=')
        if not separator or not source.strip() or not target.strip():
            raise ValueError(f'remapping {item!r} is not FROM:=TO')
        pairs.append((source.strip(), target.strip()))
    return pairs


def _node(context: LaunchContext) -> List[Node]:
    """Return the Node action with the arguments' values (remappings parsed here)."""
    remappings = parse_remappings(LaunchConfiguration('remappings').perform(context))
    return [Node(
        package=PACKAGE, executable='impact_node', name='impact_node', output='screen',
        emulate_tty=True, namespace=LaunchConfiguration('namespace'),
        remappings=remappings,
        ros_arguments=['--log-level', LaunchConfiguration('log_level')],
        parameters=[
            LaunchConfiguration('params_file'),
            {'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'),
                                            value_type=bool)}])]


def generate_launch_description() -> LaunchDescription:
    """
    Return the launch description: the arguments and the node.

    :returns: ``params_file`` (default: the package's ``config/impact_node.yaml``),
        ``use_sim_time`` (false), ``namespace`` (''), ``log_level`` (info) and ``remappings``
        ('') arguments, and an action that makes the ``impact_node`` Node from them.
    """
    default_params = PathJoinSubstitution(
        [FindPackageShare(PACKAGE), 'config', 'impact_node.yaml'])
    return LaunchDescription([
        DeclareLaunchArgument(name, default_value=default_params if default is None
                              else default, description=description)
        for name, default, description in ARGUMENTS] + [OpaqueFunction(function=_node)])
