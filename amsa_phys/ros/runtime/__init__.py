"""What the generated nodes run (imports ``rospy``; see ``rosio.ros``)."""
