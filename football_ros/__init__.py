"""football_ros: a spinning American football or rugby ball in flight, for ROS 2 Jazzy.

``football_ros.physics`` is pure numpy/scipy/numba (no ROS); ``football_ros.nodes`` wraps it in
rclpy nodes; ``football_ros.tools`` holds the recorder, the figures and the demo.
"""

import sys as _sys

from . import _early_signals

# A node program: a signal while it imports ends it with exit 0 and no traceback.
if _early_signals.is_node_program(_sys.argv, getattr(_sys, "orig_argv", ())):
    _early_signals.install()

__version__ = "0.1.0"
