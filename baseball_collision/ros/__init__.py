"""The ROS 2 shell: the only place rclpy is imported."""
