"""Pure estimation (no ROS imports): a simulated camera and the flight tracker/predictor."""

from .sensor import Camera, CameraSettings, Observation
from .tracker import FlightTracker, LandingPrediction, TrackerSettings, UpdateResult

__all__ = [
    'Camera',
    'CameraSettings',
    'Observation',
    'FlightTracker',
    'LandingPrediction',
    'TrackerSettings',
    'UpdateResult',
]
