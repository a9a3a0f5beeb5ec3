"""A scenario as a ROS 1 (catkin) package: generation (``generate``) and the nodes' runtime.

``generate``, ``graph`` and ``names`` never import ROS (``amsa-phys export ros`` works on a
machine without it); the ``runtime`` modules are what the generated nodes run and import
``rospy``.
"""
