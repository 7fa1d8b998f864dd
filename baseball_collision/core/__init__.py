"""The pure core: Python + numpy only; imports nothing above it (no ROS, no bags, no tools)."""
