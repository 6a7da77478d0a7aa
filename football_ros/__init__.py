"""football_ros: a spinning American football or rugby ball in flight, for ROS 2 Jazzy.

``football_ros.physics`` is pure numpy/scipy/numba (no ROS); ``football_ros.nodes`` wraps it in
rclpy nodes; ``football_ros.tools`` holds the recorder, the figures and the demo.
"""

__version__ = "0.1.0"
