"""
Launch ``impact_node`` with its parameters file from the package's share directory.

    ros2 launch baseball_collision impact_node.launch.py
    ros2 launch baseball_collision impact_node.launch.py \
        params_file:=/path/to/my_params.yaml use_sim_time:=true

``config/impact_node_points.yaml`` (installed beside the default) is the knob + tip example.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare

PACKAGE = 'baseball_collision'


def generate_launch_description() -> LaunchDescription:
    """
    Return the launch description: two arguments and the node.

    :returns: ``params_file`` (default: the package's ``config/impact_node.yaml``) and
        ``use_sim_time`` (default false) arguments, and the ``impact_node`` Node action.
    """
    default_params = PathJoinSubstitution(
        [FindPackageShare(PACKAGE), 'config', 'impact_node.yaml'])
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=default_params,
            description='YAML file with the impact_node parameters'),
        DeclareLaunchArgument(
            'use_sim_time', default_value='false',
            description='Follow /clock (bag replay) instead of the system clock'),
        Node(
            package=PACKAGE, executable='impact_node', name='impact_node', output='screen',
            emulate_tty=True,
            parameters=[
                LaunchConfiguration('params_file'),
                {'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'),
                                                value_type=bool)}]),
    ])
