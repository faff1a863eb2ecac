"""The ROS 2 face of a generated solver (docs/ros.md): an rclpy node over the package's cffi controller.

``env``: the environment ROS 2's PyPI wheels (or a system's Jazzy) need; ``convert``: messages to the
controller's arrays and its result back to messages; ``node``: the node itself. rclpy is imported only
by ``convert`` and ``node`` (the ``ros2`` extra: ``pip install 'humanmpc[ros2]'``).
"""
