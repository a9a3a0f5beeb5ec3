"""The ROS 2 target: a user's rclpy/rclcpp nodes in the loop (``bridge.py``), and what imports
rclpy (only this package does, and only when a run asks for ROS 2)."""
