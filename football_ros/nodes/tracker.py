# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Tracker node: ball positions from any detector in, state estimate and landing prediction out.

Subscribes ``football/observation`` (geometry_msgs/msg/PointStamped, header.stamp = capture
time) and ``football/observation_with_covariance`` (geometry_msgs/msg/PoseWithCovarianceStamped:
the position and its 3x3 covariance block, the orientation ignored), in ``frame_id`` or in any
frame /tf_static connects to it (the fix and its covariance rotated into ``frame_id``), and
runs :class:`football_ros.estimation.FlightTracker` (an unscented Kalman filter on
the package's full flight model, its predictions from a batch fit of every fix once the hand
is known, ``refine_iterations``; the filter, its choices and its limits are documented
there). Publishes ``football/estimate`` (nav_msgs/msg/Odometry with covariances),
``football/prediction/landing`` (geometry_msgs/msg/PoseWithCovarianceStamped on z = 0, whose
header.stamp is the predicted landing time), ``football/prediction/catch`` (the same through
z = ``catch_height``, where a catcher's hands are), with ``receiver_plane``
``football/prediction/receiver`` (the same through a receiver's vertical plane, x/y/z
covariance) and ``football/prediction/path`` (nav_msgs/msg/Path of the predicted rest of the
flight). Every fix is untrusted: a refused one
is counted and logged (throttled), never published from. Topics, frames, units and QoS: msg_docs/.

Several balls (:class:`football_ros.estimation.multi.MultiTracker`, up to ``max_tracks``):
each track has an id (1, 2, ... in order of start, logged as 'new throw #id' and 'throw #id
ended: why') and its own topics ``football/track_<id>/estimate``,
``football/track_<id>/prediction/landing``, ``.../catch``, ``.../receiver`` and
``football/track_<id>/prediction/path`` (:func:`qos.track_topic`), created at its start and
removed after its end; the topics without an id carry the oldest live track (the only one when
one ball flies). When fixes keep arriving for a second and no throw starts, or a track is lost
or replaced by a new throw, one log line and a WARN status on /diagnostics say why.
Predictions are throttled to ``prediction_rate`` per second of the fixes' own clock (not the
node's); a clock that jumps back (a /clock source restarted under use_sim_time) ends every
track and resets the time base, with a log line.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Point, PointStamped, PoseStamped, PoseWithCovarianceStamped
from nav_msgs.msg import Odometry, Path
import numpy as np
from rclpy.clock import JumpThreshold
from rclpy.duration import Duration
from rclpy.node import Node

from . import messages as mb
from . import qos
from .cameras import CameraInputs
from .logs import throttled
from .params import declare_all, ParamSpec
from .runner import run_node
from ..estimation import TrackerSettings
from ..estimation.camera_fusion import CameraFusion
from ..estimation.motion import X_H, X_S, X_V
from ..estimation.multi import MultiTracker
from ..estimation.static_frames import StaticFrames
from ..estimation.tracker import vertical_plane, warm_up
from ..physics.frames import attitude_with_axis, FIELD_FRAME
from ..physics.presets import PRESETS

NODE_NAME = 'football_tracker'
UNKNOWN_VARIANCE = 1e6
"""Variance [rad^2] published for the spin angle about the axis (not observable)."""


def _ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _seconds_msg(seconds: float):
    return mb.time_msg(int(round(seconds * 1e9)))


PARAMETERS = (
    ParamSpec(
        'frame_id',
        FIELD_FRAME,
        'World frame of the fixes and of every output',
        read_only=True,
        non_empty=True,
    ),
) + tuple(
    ParamSpec(*row, read_only=True)  # the filter is built once, at start-up
    for row in (
        ('ball', 'american', 'Ball preset the filter assumes', None, tuple(PRESETS)),
        ('observation_noise', 0.02, 'Fix noise, 1 sigma per axis [m]', (1e-4, 10.0)),
        (
            'model_noise',
            TrackerSettings.accel_noise,  # the filter's own default and range
            'Model-error acceleration, white [m/s^2/sqrt(Hz)]; more in gusty air',
            TrackerSettings.LIMITS['accel_noise'],
        ),
        (
            'refine_iterations',
            TrackerSettings.refine_iterations,  # the filter's own default and range
            'Batch MAP fit of every fix once the hand is known: LM steps a prediction, 0 = off',
            TrackerSettings.LIMITS['refine_iterations'],
        ),
        ('spin_rpm', 0.0, "Nominal |spin| [rev/min] of a throw, 0 = the preset's", (0.0, 3000.0)),
        (
            'stamp_jitter',
            TrackerSettings.stamp_jitter,
            "Jitter of the fixes' stamps, 1 sigma [s] (the measured one if larger)",
            TrackerSettings.LIMITS['stamp_jitter'],
        ),
        (
            'max_speed',
            TrackerSettings.max_speed,
            'Fastest start arc taken for a throw [m/s] (faster: drawn in, else refused)',
            TrackerSettings.LIMITS['max_speed'],
        ),
        (
            'min_points',
            TrackerSettings.min_points,
            'Fixes on a ballistic arc that start a throw',
            TrackerSettings.LIMITS['min_points'],
        ),
        (
            'init_window',
            TrackerSettings.init_window,
            'Window of those fixes [s] (grows to min_points + 1 intervals of a slow camera)',
            TrackerSettings.LIMITS['init_window'],
        ),
        ('gate', 21.11, 'Outlier gate: squared Mahalanobis distance', (1.0, 10000.0)),
        ('max_lag', 0.5, 'Oldest fix accepted behind the newest [s]', (0.0, 10.0)),
        ('max_gap', 0.5, 'Silence that ends a throw [s]', (0.01, 100.0)),
        (
            'max_future',
            0.5,
            'Fixes stamped more than this ahead of the node clock are refused [s], 0 = no check',
            (0.0, 100.0),
        ),
        ('path_step', 0.05, 'Time between poses of the predicted path [s]', (0.005, 1.0)),
        ('prediction_rate', 30.0, 'Landing and path predictions per second [Hz]', (0.1, 1000.0)),
        ('max_tracks', 4, 'Balls tracked at once (each on football/track_<id>/...)', (1, 64)),
        (
            'pixel_noise',
            1.0,
            "Cameras' detection noise: centre and apparent width, 1 sigma [px]",
            (0.01, 100.0),
        ),
        (
            'catch_height',
            1.2,
            'Height whose downward crossing is predicted (football/prediction/catch) [m], 0 = off',
            (0.0, 100.0),
        ),
        (
            'receiver_plane',
            False,
            "Predict the crossing of a receiver's vertical plane (football/prediction/receiver)",
        ),
        ('receiver_x', 0.0, "A point of the receiver's plane, x in frame_id [m]", (-1e4, 1e4)),
        ('receiver_y', 0.0, "A point of the receiver's plane, y in frame_id [m]", (-1e4, 1e4)),
        (
            'receiver_heading',
            0.0,
            "Direction the ball crosses the receiver's plane in, from +x to +y [deg]",
            (-360.0, 360.0),
        ),
        ('wind_x', 0.0, 'Known steady wind, x component in frame_id [m/s]', (-50.0, 50.0)),
        ('wind_y', 0.0, 'Known steady wind, y component in frame_id [m/s]', (-50.0, 50.0)),
        (
            'wind_sigma',
            0.0,
            'Unknown horizontal wind beyond wind_x/y, estimated: prior sigma [m/s], 0 = off',
            (0.0, 30.0),
        ),
        (
            'gust_rate',
            TrackerSettings.gust_rate,
            'Gusts: each filter has a gusty twin, the wind a random walk of this rate '
            '[m/s/sqrt(s)], mixed by likelihood (an unmodelled wind taken in); 0 = still air only',
            TrackerSettings.LIMITS['gust_rate'],
        ),
        (
            'gust_prior',
            TrackerSettings.gust_prior,
            'Odds of gusty air before the fixes tell, kept as a floor while still air fits '
            '(larger: gusts caught sooner, wider in still air; 0.5 on a gusty day)',
            TrackerSettings.LIMITS['gust_prior'],
        ),
        (
            'unstable_fits',
            TrackerSettings.unstable_fits,
            'Kicks that may tumble (S_g < 1): multi-start fits mixing the basins they find, '
            'far nearer the bound on screw kicks and punts (more CPU a kick)',
        ),
        (
            'carry_over',
            False,
            'Start each throw from the drag/lift scales (and wind) the last landed throw learnt',
        ),
    )
) + (
    ParamSpec(
        'cameras',
        [''],
        'Cameras whose football/camera/<name>/detections are fused as pixels (intrinsics from '
        "camera_info, poses from /tf_static); [] or [''] = none",
        read_only=True,
        optional=True,
    ),
)


class TrackerNode(Node):
    """Thin adapter: fixes in, estimate, landing and path out."""

    PARAMETERS = PARAMETERS

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        declare_all(self, PARAMETERS)
        self.tracker = MultiTracker(
            TrackerSettings(
                noise=self.observation_noise,
                accel_noise=self.model_noise,
                refine_iterations=int(self.refine_iterations),
                ball=self.ball,
                spin_rpm=self.spin_rpm or None,
                stamp_jitter=self.stamp_jitter,
                min_points=int(self.min_points),
                init_window=self.init_window,
                gate=self.gate,
                max_lag=self.max_lag,
                max_gap=self.max_gap,
                max_future=max(self.max_future, 1e-9),
                wind=(self.wind_x, self.wind_y),
                wind_sigma=self.wind_sigma,
                gust_rate=self.gust_rate,
                gust_prior=self.gust_prior,
                max_speed=self.max_speed,
                unstable_fits=bool(self.unstable_fits),
            ),
            max_tracks=int(self.max_tracks),
            carry_over=bool(self.carry_over),
        )
        self.plane = (
            vertical_plane(self.receiver_x, self.receiver_y, self.receiver_heading)
            if self.receiver_plane
            else None
        )
        self._streams = {None: self._stream(None)}  # None: the primary stream (legacy topics)
        self.create_subscription(PointStamped, qos.OBSERVATION, self._on_fix, qos.STATE)
        self.create_subscription(
            PoseWithCovarianceStamped, qos.OBSERVATION_COV, self._on_fix, qos.STATE
        )
        self.frames = StaticFrames()
        if mb.TFMessage is not None:
            self.create_subscription(
                mb.TFMessage, qos.TF_STATIC, self._on_tf_static, qos.TF_STATIC_QOS
            )
        self._diag_pub = self.create_publisher(
            DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS
        )
        self.diagnostic_name = f'football_ros: {self.get_fully_qualified_name()}'
        names = [name for name in self.cameras if name]
        bad = [name for name in names if not name.replace('_', 'a').isalnum()]
        if bad:
            raise ValueError(f"parameter 'cameras': {bad[0][:40]!r} is not a camera name "
                             '(letters, digits and _)')
        self._fusion = CameraFusion(self.tracker, self.pixel_noise, PRESETS[self.ball].diameter)
        self._camera_inputs = (
            CameraInputs(self, names, self.frame_id, self._on_detection) if names else None
        )
        self._jump = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(seconds=-1.0)),
            post_callback=self._on_clock_jump,
        )
        warm_up(self.tracker.settings)  # every kernel of the tracker, before 'ready'
        self.get_logger().info(
            f"ready: tracking '{self.resolve_topic_name(qos.OBSERVATION)}' in "
            f"'{self.frame_id}' ({self.ball}, noise {self.observation_noise:g} m)"
        )

    def _on_clock_jump(self, jump) -> None:
        """Reset the time base: the node's clock went back (a /clock source restarted)."""
        try:
            back = -jump.delta.nanoseconds * 1e-9
            if self.tracker.reset_time_base():  # else nothing to reset (start-up)
                self._log_events()
                for stream in self._streams.values():
                    stream.throttle.reset()
                self.get_logger().warning(
                    f'the clock jumped back {back:.3f} s: time base reset'
                )
        except Exception as exc:  # noqa: BLE001 - never from a clock callback
            self.get_logger().error(f'clock jump not handled: {exc!r}'[:300])

    def _on_tf_static(self, msg) -> None:
        """Record the static transforms (each checked; a bad one is refused with a log line)."""
        try:
            for tf in msg.transforms[:256]:
                tr, rot = tf.transform.translation, tf.transform.rotation
                try:
                    self.frames.add(
                        tf.header.frame_id, tf.child_frame_id, (tr.x, tr.y, tr.z),
                        (rot.x, rot.y, rot.z, rot.w),
                    )
                except ValueError as exc:
                    throttled(
                        self.get_logger(), 'warning',
                        f'/tf_static transform refused: {exc}',
                        2.0,
                    )
        except Exception as exc:  # noqa: BLE001 - a bad message must never stop the node
            self.get_logger().error(f'/tf_static ignored after an internal error: {exc!r}'[:300])

    def _on_fix(self, msg) -> None:
        try:
            self._handle(msg)
        except Exception as exc:  # noqa: BLE001 - a bad fix must never stop the node
            self.get_logger().error(f'fix ignored after an internal error: {exc!r}'[:300])

    def _handle(self, msg) -> None:
        fix = fix_of(msg, self.frame_id, self.frames)
        if isinstance(fix, str):
            throttled(self.get_logger(), 'warning', f'fix refused: {fix}', 2.0)
            return
        position, covariance = fix
        stamp = _ns(msg.header.stamp) * 1e-9
        now = self.get_clock().now().nanoseconds * 1e-9 if self.max_future > 0 else None
        track_id, result = self.tracker.update(stamp, position, now, covariance)
        self._took(track_id, result, position[:2], stamp)

    def _on_detection(self, stamp: float, name: str, camera, center, width: float) -> None:
        """One camera detection (nodes/cameras.py): fused as pixels (estimation/camera_fusion)."""
        now = self.get_clock().now().nanoseconds * 1e-9 if self.max_future > 0 else None
        track_id, result = self._fusion.observe(stamp, camera, center, width, now, name)
        if track_id is None and isinstance(result, str):
            self._camera_inputs.refuse(name, f'detection refused: {result}')
            return
        est = self.tracker.taken_by.estimate if result.used else None
        seen = est[1][:2] if est is not None else (math.nan, math.nan)
        self._took(track_id, result, seen, stamp)

    def _took(self, track_id, result, seen, stamp: float) -> None:
        """Publish and log what a fix (a position or a detection) changed."""
        if result.status == 'started' and result.reason:  # the clock of the fixes jumped back
            self.get_logger().warning(result.reason)
            for stream in self._streams.values():
                stream.throttle.reset()
        self._log_events()
        if not result.used:
            if result.status != 'candidate':
                throttled(
                    self.get_logger(), 'warning',
                    f'fix refused ({result.status}): {result.reason}',
                    2.0,
                )
            return
        tracker = self.tracker.taken_by
        primary = track_id == min(set(self.tracker.tracks) | {track_id})
        for key in (track_id, None) if primary else (track_id,):
            stream = self._streams.get(key)
            if stream is None:
                continue
            self._publish_estimate(tracker, stream)
            est = tracker.estimate
            if result.landed or (est is not None and stream.throttle.due(est[0])):
                self._publish_predictions(tracker, stream, result.landed and key is None)
        self._say(track_id, tracker, result.landed, seen, stamp)
        if result.landed:
            self._drop_stream(track_id)

    def _say(self, track_id, tracker, landed: bool, seen, stamp: float) -> None:
        """One log line per throw at lock-on (the hand decided) and one at the landing."""
        stream = self._streams.get(track_id)
        if stream is None or tracker.track is None:
            return
        if stream.locked is None and (tracker.hand is not None or landed):
            pred = tracker.predict_landing()
            if pred is not None:
                stream.locked = pred
                sigma = math.sqrt(max(float(np.trace(pred.covariance)), 0.0))
                self.get_logger().info(
                    f'throw #{track_id} locked on at t = {stamp:.3f} s: landing predicted at '
                    f'x = {pred.position[0]:.2f} m, y = {pred.position[1]:.2f} m '
                    f'(+/- {sigma:.2f} m) at t = {pred.time:.3f} s'
                )
        if landed and stream.locked is not None:
            pred = stream.locked
            err = math.hypot(pred.position[0] - seen[0], pred.position[1] - seen[1])
            self.get_logger().info(
                f'throw #{track_id} landed: seen at x = {seen[0]:.2f} m, y = {seen[1]:.2f} m at '
                f't = {stamp:.3f} s; the lock-on prediction was {err:.2f} m and '
                f'{pred.time - stamp:+.3f} s off'
            )

    def _stream(self, track_id):
        """Create the publishers (and throttle) of one track; None: the legacy topics."""

        def name(topic):
            return topic if track_id is None else qos.track_topic(track_id, topic)

        return _Stream(
            self.create_publisher(Odometry, name(qos.ESTIMATE), qos.STATE),
            self.create_publisher(PoseWithCovarianceStamped, name(qos.LANDING), qos.STATE),
            self.create_publisher(Path, name(qos.PREDICTED_PATH), qos.STATE),
            PredictionThrottle(self.prediction_rate),
            self.create_publisher(PoseWithCovarianceStamped, name(qos.CATCH), qos.STATE)
            if self.catch_height > 0.0
            else None,
            self.create_publisher(PoseWithCovarianceStamped, name(qos.RECEIVER), qos.STATE)
            if self.plane is not None
            else None,
        )

    def _drop_stream(self, track_id) -> None:
        stream = self._streams.pop(track_id, None) if track_id is not None else None
        if stream is not None:
            for pub in (stream.estimate, stream.landing, stream.path, stream.catch,
                        stream.receiver):
                if pub is not None:
                    self.destroy_publisher(pub)

    def _log_events(self) -> None:
        """Log the tracks started and ended; open and close their streams."""
        events, self.tracker.events = self.tracker.events, []
        for ev in events:
            if ev.kind == 'no_start':
                self.get_logger().warning(ev.reason)
                self._diagnose('no_start', ev.reason, ev.time)
            elif ev.kind == 'started':
                self._streams[ev.track_id] = self._stream(ev.track_id)
                self.get_logger().info(
                    f'new throw #{ev.track_id} at t = {ev.time:.3f} s '
                    f"(on '{qos.track_topic(ev.track_id, 'football/estimate')}' ...)"
                )
            else:
                if ev.reason != 'landed':
                    self._drop_stream(ev.track_id)
                    self._diagnose('track_ended', f'throw #{ev.track_id} ended: {ev.reason}',
                                   ev.time)
                self.get_logger().info(f'throw #{ev.track_id} ended: {ev.reason}')

    def _diagnose(self, event: str, text: str, t: float) -> None:
        """Publish one WARN status on /diagnostics (stamped ``t`` [s] of the fixes' clock)."""
        msg = DiagnosticArray()
        if _stampable(t):
            msg.header.stamp = _seconds_msg(t)
        msg.status = [mb.diagnostic_status(
            self.diagnostic_name, 'WARN', text, {'event': event, 'time': float(t)}
        )]
        self._diag_pub.publish(msg)

    def _publish_estimate(self, tracker, stream) -> None:
        est = tracker.estimate
        if est is None:
            return
        t, x, P = est
        msg = estimate_message(t, x, P, self.frame_id, tracker.ball.inertia_ratio)
        if msg is not None:
            stream.estimate.publish(msg)

    def _publish_predictions(self, tracker, stream, log_landing: bool) -> None:
        height = self.catch_height if stream.catch is not None else -math.inf
        # One flight of the sigma points for all three.
        pred, catch, through = tracker.predict_planes(height, self.plane)
        if pred is not None:
            msg = landing_message(pred, self.frame_id)
            if msg is not None:
                stream.landing.publish(msg)
                if log_landing:
                    self.get_logger().info(
                        f'landed: predicted landing at x = {pred.position[0]:.3f} m, '
                        f'y = {pred.position[1]:.3f} m, t = {pred.time:.3f} s'
                    )
        for pub, crossing in ((stream.catch, catch), (stream.receiver, through)):
            msg = landing_message(crossing, self.frame_id) if crossing is not None else None
            if pub is not None and msg is not None:
                pub.publish(msg)
        path = tracker.predict_path(self.path_step)
        est = tracker.estimate
        if path is not None and est is not None:
            msg = path_message(est[0], *path, self.frame_id)
            if msg is not None:
                stream.path.publish(msg)


@dataclass
class _Stream:
    estimate: object
    landing: object
    path: object
    throttle: 'PredictionThrottle'
    catch: object | None
    receiver: object | None
    locked: object | None = None  # the landing predicted at lock-on


class PredictionThrottle:
    """
    At most ``rate`` [Hz] predictions per second of the fixes' own clock.

    On the observations' clock, not the node's: a stranger's or a stalled /clock must not
    starve (or flood) the predictions; a time that goes back re-arms it.
    """

    def __init__(self, rate: float) -> None:
        self.period = 1.0 / rate
        self._last = -math.inf

    def due(self, t: float) -> bool:
        """Tell whether a prediction is due at ``t`` [s] (the estimate's time); if so, take it."""
        if t < self._last:  # the fixes' clock went back
            self._last = -math.inf
        if t - self._last >= self.period - 1e-9:
            self._last = t
            return True
        return False

    def reset(self) -> None:
        """Forget the last prediction's time."""
        self._last = -math.inf


def fix_of(msg, frame_id: str, frames: StaticFrames):
    """
    Return (position (3,) [m], covariance (3, 3) [m^2] or None) of a fix in ``frame_id``.

    ``msg`` a PointStamped (no covariance) or a PoseWithCovarianceStamped (its position block);
    in ``frame_id`` or a frame ``frames`` connects to it (rotated and moved into it). A str
    (the reason, naming the field) if the fix cannot be used.
    """
    source = msg.header.frame_id
    if isinstance(msg, PointStamped):
        p, cov = msg.point, None
    else:
        p = msg.pose.pose.position
        full = np.asarray(msg.pose.covariance, dtype=float)
        if full.size != 36 or not np.all(np.isfinite(full)):
            return 'pose.covariance must be 36 finite numbers'
        cov = full.reshape(6, 6)[:3, :3]
        if not np.any(cov):  # all zero: not given (the ROS convention), the node's noise
            cov = None
    position = np.array([p.x, p.y, p.z], dtype=float)
    if source != frame_id:
        transform = frames.lookup(frame_id, source)
        if transform is None:
            return (f"header.frame_id '{source[:40]}' is not '{frame_id}' nor a frame "
                    '/tf_static connects to it')
        R, t = transform
        position = R @ position + t
        cov = None if cov is None else R @ cov @ R.T
    return position, cov


def _finite(*arrays) -> bool:
    return all(np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays)


def _stampable(*seconds) -> bool:
    """Tell whether every time [s] fits a builtin_interfaces/Time (0 <= t < 2^31 s)."""
    return all(math.isfinite(t) and 0.0 <= t < 2.0**31 - 1.0 for t in seconds)


def estimate_message(
    t: float, x: np.ndarray, P: np.ndarray, frame_id: str, inertia_ratio: float
) -> Odometry | None:
    """
    Odometry of the estimate at ``t`` [s].

    Pose (orientation with body x = the estimated axis) and twist (velocity and angular
    velocity) both in ``frame_id`` (child_frame_id = frame_id), 6x6 covariances (x y z then
    rotations about x y z of that frame); None if anything is non-finite.
    """
    r, v, s, h = x[:3], x[X_V:X_V + 3], x[X_S:X_S + 3], x[X_H:X_H + 3]
    h1 = float(h @ s)
    omega = h + (h1 / inertia_ratio - h1) * s  # w = h - h1 s + p s, p = h1 I_t / I_s
    q = attitude_with_axis(s)
    pose_cov = np.zeros((6, 6))
    pose_cov[:3, :3] = P[:3, :3]
    # Rotation covariance in the world frame: the axis's, plus an unknown spin angle about s.
    pose_cov[3:, 3:] = P[X_S:X_S + 3, X_S:X_S + 3] + UNKNOWN_VARIANCE * np.outer(s, s)
    twist_cov = np.zeros((6, 6))
    twist_cov[:3, :3] = P[X_V:X_V + 3, X_V:X_V + 3]
    twist_cov[3:, 3:] = P[X_H:X_H + 3, X_H:X_H + 3]
    if not (_finite(r, v, q, omega, pose_cov, twist_cov) and _stampable(t)):
        return None
    msg = Odometry(header=mb.header(_seconds_msg(t), frame_id), child_frame_id=frame_id)
    msg.pose.pose.position = Point(x=float(r[0]), y=float(r[1]), z=float(r[2]))
    msg.pose.pose.orientation = mb.quaternion(q)
    msg.pose.covariance = [float(c) for c in pose_cov.ravel()]
    msg.twist.twist.linear = mb.vector3(v)
    msg.twist.twist.angular = mb.vector3(omega)
    msg.twist.covariance = [float(c) for c in twist_cov.ravel()]
    return msg


def landing_message(pred, frame_id: str) -> PoseWithCovarianceStamped | None:
    """
    Build the predicted landing.

    header.stamp = predicted landing (or crossing) time, position on the plane, covariance: the
    prediction's x/y block (a horizontal plane, z 0) or x/y/z block (a vertical plane); rotations
    0 (not estimated).
    """
    cov = np.zeros((6, 6))
    k = pred.covariance.shape[0]
    cov[:k, :k] = pred.covariance
    if not (_finite(pred.position, cov) and _stampable(pred.time)):
        return None
    msg = PoseWithCovarianceStamped(header=mb.header(_seconds_msg(pred.time), frame_id))
    p = pred.position
    msg.pose.pose.position = Point(x=float(p[0]), y=float(p[1]), z=float(p[2]))
    msg.pose.pose.orientation.w = 1.0
    msg.pose.covariance = [float(c) for c in cov.ravel()]
    return msg


def path_message(t: float, times: np.ndarray, positions: np.ndarray, frame_id: str) -> Path | None:
    """nav_msgs/Path stamped ``t`` [s]; pose k stamped with its predicted time."""
    if not (_finite(times, positions) and _stampable(t, *times)):
        return None
    msg = Path(header=mb.header(_seconds_msg(t), frame_id))
    for tk, p in zip(times, positions):
        pose = PoseStamped(header=mb.header(_seconds_msg(float(tk)), frame_id))
        pose.pose.position = Point(x=float(p[0]), y=float(p[1]), z=float(p[2]))
        pose.pose.orientation.w = 1.0
        msg.poses.append(pose)
    return msg


def main(argv=None) -> int:
    return run_node(TrackerNode, argv, 'tracker')


if __name__ == '__main__':
    raise SystemExit(main())
