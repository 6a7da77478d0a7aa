"""Pure physics of a spinning football (no ROS imports). Frames and units: docs/physics.md."""

from .flight import CSV_HEADER, Flight, Trajectory
from .linear_theory import LinearModes, linear_modes
from .presets import PRESETS, BallPreset, get_preset
from .release import InitialState, Release, ReleaseError

__all__ = ["CSV_HEADER", "Flight", "Trajectory", "LinearModes", "linear_modes", "PRESETS",
           "BallPreset", "get_preset", "InitialState", "Release", "ReleaseError"]
