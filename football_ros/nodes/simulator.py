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
Real-time simulator node: flies the ball ordered by the release node and publishes its state.

Pacing: a dedicated thread wakes at absolute monotonic deadlines k / publish_rate. Each tick
advances the flight by real_time_factor / publish_rate of simulated time (the integrator keeps
its own fixed step), so there is no drift; a tick that comes late is still published, with its
scheduled stamp, and counted as an overrun on /diagnostics. All messages of one tick carry the
same stamp. After the landing the landed state is republished at ``hold_rate`` (0 = never).
Topics, frames, units and QoS: msg_docs/.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass, field
import gc
import math
import sys
import threading
import time
import traceback

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

from . import messages as mb
from . import qos
from .observation_hook import ObservationHook
from .params import declare
from .runner import run_node
from ..physics import Release
from ..physics.flight import BallSample, Flight
from ..physics.frames import BODY_FRAME, FIELD_FRAME
from ..physics.release import RPM
from ..requests import capped, FlightOrder, load_strict

NODE_NAME = 'football_simulator'
DIAGNOSTIC_NAME = 'football_ros: simulator'
MODEL_CHOICES = ('release', 'paper', 'full')
MAX_CATCH_UP_S = 1.0
"""A stall longer than this is not replayed: its ticks are skipped (and counted)."""


@dataclass
class _FlightRun:
    """The flight in the air and its bookkeeping (guarded by the node's lock)."""

    order: FlightOrder
    flight: Flight
    ticks: int = 0
    tick_dt: float = 0.0  # simulated seconds per tick for this run
    time_offset: float = 0.0  # simulated seconds flown before the last rate change
    landed_reported: bool = False
    last_hold_ns: int = 0
    last_marker_ns: int | None = None
    trail: collections.deque = field(default_factory=lambda: collections.deque(maxlen=500))

    @property
    def time(self) -> float:
        return self.time_offset + self.ticks * self.tick_dt


class SimulatorNode(Node):
    """
    Simulator node: the ball in flight, paced in real time.

    Publishes pose, odometry, spin axis, alpha/beta (and their linear prediction), markers and
    diagnostics of the ball in flight, paced in real time.
    """

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        self.publish_rate = declare(
            self,
            'publish_rate',
            100.0,
            'State messages per second of wall time [Hz]',
            (1.0, 2000.0),
        )
        self.integration_step = declare(
            self,
            'integration_step',
            0.001,
            'Fixed RK4 step of the integrator [s] (next flight)',
            (1e-5, 0.01),
        )
        self.real_time_factor = declare(
            self, 'real_time_factor', 1.0, 'Simulated seconds per wall second', (0.01, 100.0)
        )
        self.publish_clock = declare(
            self,
            'publish_clock',
            False,
            'Publish /clock (simulated time) and stamp messages with it',
        )
        self.frame_id = declare(
            self, 'frame_id', FIELD_FRAME, 'World frame (REP-103: x downfield, z up)'
        )
        self.child_frame_id = declare(
            self,
            'child_frame_id',
            BODY_FRAME,
            'Body frame of the ball (x = spin axis toward the leading nose)',
        )
        self.marker_rate = declare(
            self, 'marker_rate', 30.0, 'RViz markers per second [Hz], 0 = off', (0.0, 200.0)
        )
        self.trail_length = declare(
            self, 'trail_length', 500, 'Points kept in the trail marker', (0, 100000)
        )
        self.hold_rate = declare(
            self,
            'hold_rate',
            1.0,
            'Rate at which the landed state is republished [Hz], 0 = never',
            (0.0, 100.0),
        )
        self.diagnostics_rate = declare(
            self, 'diagnostics_rate', 1.0, 'Periodic /diagnostics [Hz]', (0.1, 100.0)
        )
        self.model = declare(
            self,
            'model',
            'release',
            "Equations of motion: 'release' (as each release asks), 'paper' or 'full'",
        )
        # --- TF hook (jazzy): the ball as the frame child_frame_id in frame_id on /tf ---
        self.publish_tf = declare(
            self,
            'publish_tf',
            mb.TFMessage is not None,
            'Publish the ball on /tf (frame_id -> child_frame_id)',
        )
        self._tf_pub = (
            None
            if mb.TFMessage is None
            else self.create_publisher(mb.TFMessage, qos.TF, qos.TF_QOS)
        )
        self._tf_last = (None, -1)  # (publish_clock, stamp ns) of the last transform sent
        if self.model not in MODEL_CHOICES:
            raise ValueError(
                f"parameter model must be one of {', '.join(MODEL_CHOICES)}, got '{self.model}'"
            )
        self._observation = ObservationHook(self)  # simulated camera: observation_* (tracker)
        self.add_on_set_parameters_callback(self._on_parameters)

        self._pubs = {
            qos.POSE: self.create_publisher(PoseStamped, qos.POSE, qos.STATE),
            qos.ODOM: self.create_publisher(Odometry, qos.ODOM, qos.STATE),
            qos.SPIN_AXIS: self.create_publisher(Vector3Stamped, qos.SPIN_AXIS, qos.STATE),
            qos.AERO_ANGLES: self.create_publisher(Vector3Stamped, qos.AERO_ANGLES, qos.STATE),
            qos.AERO_ANGLES_LINEAR: self.create_publisher(
                Vector3Stamped, qos.AERO_ANGLES_LINEAR, qos.STATE
            ),
        }
        self._markers_pub = self.create_publisher(MarkerArray, qos.MARKERS, qos.MARKERS_QOS)
        self._diag_pub = self.create_publisher(
            DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS
        )
        self._clock_pub = self.create_publisher(Clock, qos.CLOCK, qos.CLOCK_QOS)
        self._ack_pub = self.create_publisher(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
        self.create_subscription(String, qos.FLIGHT_ORDER, self._on_order, qos.ORDER)
        self.create_service(Trigger, qos.RESET_SERVICE, self._on_reset)
        self.create_service(SetBool, qos.PAUSE_SERVICE, self._on_pause)

        self._lock = threading.Lock()
        self._run: _FlightRun | None = None
        self._last_order: FlightOrder | None = None
        self._paused = False
        self._sim_clock_ns = 0
        self._events: list[tuple[str, str, str]] = []  # (level, event, message) to report
        self.stats = {'ticks': 0, 'overruns': 0, 'skipped': 0, 'max_late_ms': 0.0}
        self._overruns_reported = 0
        _warm_up()
        gc.freeze()  # start-up objects leave the collector's generations: shorter GC pauses
        sys.setswitchinterval(1e-4)  # the pacer gets the GIL within 0.1 ms (default: 5 ms)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._pace, name='football-pacer', daemon=True)
        self._thread.start()
        self.get_logger().info(
            f'ready: {self.publish_rate:g} Hz, step {self.integration_step:g} s, real-time factor '
            f'{self.real_time_factor:g}; waiting for flights on '
            f"'{self.resolve_topic_name(qos.FLIGHT_ORDER)}'"
        )

    # --- parameters, services, orders (executor thread) --------------------------------------
    def _on_parameters(self, params) -> SetParametersResult:
        """Check every change first (ranges are enforced by the descriptors), then apply all."""
        for p in params:
            if p.name in ('frame_id', 'child_frame_id') and not p.value:
                return SetParametersResult(successful=False, reason=f'{p.name} must not be empty')
            if p.name == 'model' and p.value not in MODEL_CHOICES:
                return SetParametersResult(
                    successful=False, reason=f'model must be one of {", ".join(MODEL_CHOICES)}'
                )
        with self._lock:
            for p in params:
                if p.name != 'use_sim_time':
                    setattr(self, p.name, p.value)
            if self._run is not None:
                self._rebase(self._run)
        return SetParametersResult(successful=True)

    def _rebase(self, run: _FlightRun) -> None:
        """Keep the flown time and continue with the current rate and real-time factor."""
        run.time_offset, run.ticks = run.time, 0
        run.tick_dt = self.real_time_factor / self.publish_rate
        run.trail = collections.deque(run.trail, maxlen=max(self.trail_length, 1))

    def _on_order(self, msg: String) -> None:
        """
        Fly a valid order and acknowledge it (OK), or refuse it with the reason (ERROR).

        Every order gets exactly one acknowledgement on football/flight/ack, named by the
        order's ``order`` id (else its ``id``): the release node answers its client from it.
        """
        name = 'unknown'
        try:
            name = _order_name(msg.data)
            order = FlightOrder.from_json(msg.data)
            flight = order.flight(self.integration_step, self._model_override())
        except ValueError as exc:
            reason = capped(str(exc))
            self.get_logger().error(f"refused flight order '{name}': {reason}")
            self._acknowledge(name, 'ERROR', reason, {})
            return
        except Exception as exc:  # never let one order take the simulator down
            self.get_logger().error(
                f"flight order '{name}': internal error\n{traceback.format_exc()}"
            )
            self._acknowledge(name, 'ERROR', f'internal error ({type(exc).__name__})', {})
            return
        self._start(order, flight)
        self._acknowledge(
            name,
            'OK',
            f"flying '{order.request_id}'",
            {'request_id': order.request_id, 'model': flight.model},
        )

    def _acknowledge(self, name: str, level: str, message: str, values: dict) -> None:
        self._ack_pub.publish(
            mb.diagnostic_status(
                name, level, message, values, hardware_id=self.get_fully_qualified_name()
            )
        )

    def _start(self, order: FlightOrder, flight: Flight) -> None:
        modes = flight.modes
        v = order.initial.velocity
        text = (
            f"flight '{order.request_id}': {order.ball_name} released at "
            f'{np.linalg.norm(v):.2f} m/s, '
            f'{math.degrees(modes.flight_path_angle):.1f} deg, {order.initial.spin / RPM:.0f} rpm'
            f' ({"stable" if modes.stable else "gyroscopically UNSTABLE"}, equilibrium sideslip '
            f'{math.degrees(modes.equilibrium_sideslip):.2f} deg)'
        )
        with self._lock:
            replaced = self._run is not None and self._run.flight.landing_time is None
            run = _FlightRun(order, flight)
            self._rebase(run)
            self._run, self._last_order = run, order
            self._events.append(('OK' if modes.stable else 'WARN', 'released', text))
        if replaced:
            self.get_logger().info('the flight in the air is replaced by a new release')
        if modes.stable:
            self.get_logger().info(text)
        else:
            self.get_logger().warning(text)

    def _on_reset(self, _request, response):
        with self._lock:
            order = self._last_order
        if order is None:
            response.success, response.message = (
                False,
                'no flight to reset: nothing was released yet',
            )
            return response
        try:
            flight = order.flight(self.integration_step, self._model_override())
        except ValueError as exc:
            response.success, response.message = False, f'cannot restart: {capped(str(exc))}'
            return response
        self._start(order, flight)
        response.success, response.message = (
            True,
            f"flight '{order.request_id}' restarted from its release",
        )
        return response

    def _model_override(self) -> str | None:
        return None if self.model == 'release' else self.model

    def _on_pause(self, request, response):
        with self._lock:
            self._paused = bool(request.data)
        response.success = True
        response.message = 'paused' if request.data else 'running'
        self.get_logger().info(f'simulation {response.message}')
        return response

    # --- pacing thread -----------------------------------------------------------------------
    def _pace(self) -> None:
        mono0 = time.monotonic_ns()
        ros0 = self.get_clock().now().nanoseconds
        next_due = mono0
        next_diag = mono0
        while not self._stop.is_set():
            period_ns = int(round(1e9 / self.publish_rate))
            now = time.monotonic_ns()
            if now < next_due:
                time.sleep((next_due - now) * 1e-9)
                continue
            late = now - next_due
            behind = late // period_ns
            self.stats['max_late_ms'] = max(self.stats['max_late_ms'], late * 1e-6)
            if behind:
                self.stats['overruns'] += int(behind)
                replay = min(int(behind), int(MAX_CATCH_UP_S * self.publish_rate))
                self.stats['skipped'] += int(behind) - replay
                next_due += (int(behind) - replay) * period_ns
            try:
                while next_due <= now:
                    self._tick(ros0 + (next_due - mono0), period_ns)
                    next_due += period_ns
                if now >= next_diag:
                    self._publish_diagnostics(None)
                    next_diag = now + int(1e9 / self.diagnostics_rate)
            except Exception:
                if not self.context.ok():  # Ctrl-C / SIGTERM shut rclpy down under us: just stop
                    return
                raise

    def _tick(self, wall_stamp_ns: int, period_ns: int) -> None:
        with self._lock:
            self.stats['ticks'] += 1
            if not self._paused:
                self._sim_clock_ns += int(period_ns * self.real_time_factor)
            stamp = mb.time_msg(self._sim_clock_ns if self.publish_clock else wall_stamp_ns)
            if self.publish_clock:
                self._clock_pub.publish(Clock(clock=stamp))
            run = self._run
            if run is None or self._paused:
                return
            if run.landed_reported:
                if self.hold_rate <= 0 or wall_stamp_ns - run.last_hold_ns < 1e9 / self.hold_rate:
                    return
                run.last_hold_ns = wall_stamp_ns
            self._observation.tick(run, stamp)  # simulated camera (observation_hook.py)
            sample = run.flight.sample(run.time)
            run.ticks += 1
            landed_now = sample.landed and not run.landed_reported
            if landed_now:
                run.landed_reported, run.last_hold_ns = True, wall_stamp_ns
                self._events.append(
                    (
                        'OK',
                        'landed',
                        f"flight '{run.order.request_id}' "
                        + _landed_text(sample.position, sample.t),
                    )
                )
            self._publish_state(sample, stamp)
            self._maybe_publish_markers(run, sample, stamp, wall_stamp_ns, force=landed_now)
            events, self._events = self._events, []
        for _level, event, text in events:
            if event == 'landed':
                self.get_logger().info(text)
        if events:
            self._publish_diagnostics(events)

    def _publish_state(self, sample: BallSample, stamp) -> None:
        frame = self.frame_id
        self._pubs[qos.POSE].publish(mb.pose_stamped(sample, stamp, frame))
        self._pubs[qos.ODOM].publish(mb.odometry(sample, stamp, frame, self.child_frame_id))
        self._pubs[qos.SPIN_AXIS].publish(mb.vector3_stamped(sample.axis, stamp, frame))
        self._pubs[qos.AERO_ANGLES].publish(mb.vector3_stamped(sample.aero_angles, stamp, frame))
        linear = [*sample.aero_angles_linear, math.nan]
        self._pubs[qos.AERO_ANGLES_LINEAR].publish(mb.vector3_stamped(linear, stamp, frame))
        self._publish_tf(sample, stamp)

    def _publish_tf(self, sample: BallSample, stamp) -> None:
        """
        TF hook (jazzy).

        One transform per published state; tf2 rejects a repeated or older stamp for a
        frame, so a stamp that does not advance on the same clock is skipped.
        """
        ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        clock, last_ns = self._tf_last
        if (
            self._tf_pub is None
            or not self.publish_tf
            or (clock == self.publish_clock and ns <= last_ns)
        ):
            return
        self._tf_last = (self.publish_clock, ns)
        self._tf_pub.publish(mb.tf_message(sample, stamp, self.frame_id, self.child_frame_id))

    def _maybe_publish_markers(
        self, run: _FlightRun, sample: BallSample, stamp, wall_ns: int, force: bool
    ) -> None:
        if self.marker_rate <= 0:
            return
        last = run.last_marker_ns
        if not force and last is not None and wall_ns - last < 1e9 / self.marker_rate:
            return
        run.last_marker_ns = wall_ns
        run.trail.append(sample.position)
        ball = run.flight.ball
        self._markers_pub.publish(
            mb.markers(sample, run.trail, stamp, self.frame_id, ball.length, ball.diameter)
        )

    def _publish_diagnostics(self, events) -> None:
        with self._lock:
            run, paused, stats = self._run, self._paused, dict(self.stats)
            stamp = mb.time_msg(
                self._sim_clock_ns if self.publish_clock else self.get_clock().now().nanoseconds
            )
        values = {
            'publish_rate': self.publish_rate,
            'real_time_factor': self.real_time_factor,
            'ticks': stats['ticks'],
            'overruns': stats['overruns'],
            'skipped_ticks': stats['skipped'],
            'max_late_ms': round(stats['max_late_ms'], 3),
        }
        level, message = 'OK', 'idle: waiting for a release'
        if run is not None:
            flight = run.flight
            values.update(
                {
                    'flight_id': run.order.request_id,
                    'ball': run.order.ball_name,
                    'flight_time': run.time,
                    'stable': flight.modes.stable,
                }
            )
            if flight.landing_time is not None:
                landing = flight.state_at(flight.landing_time)
                values.update(
                    {
                        'time_of_flight': flight.landing_time,
                        'landing_x': float(landing[0]),
                        'landing_y': float(landing[1]),
                    }
                )
                message = _landed_text(landing, flight.landing_time)
            else:
                message = f'flying: t = {run.time:.3f} s'
            if not flight.modes.stable:
                level, message = 'WARN', message + ' (gyroscopically unstable)'
        if paused:
            message = 'paused; ' + message
        statuses = []
        for ev_level, event, text in events or []:
            statuses.append(
                mb.diagnostic_status(
                    DIAGNOSTIC_NAME + ' event', ev_level, text, dict(values, event=event)
                )
            )
        new_overruns = stats['overruns'] - self._overruns_reported
        if events is None:  # periodic status: overruns since the previous one make it WARN
            self._overruns_reported = stats['overruns']
        if new_overruns:
            level = 'WARN' if level == 'OK' else level
            message += f'; {new_overruns} late tick(s) caught up since the last status'
        statuses.append(mb.diagnostic_status(DIAGNOSTIC_NAME, level, message, values))
        self._diag_pub.publish(DiagnosticArray(header=mb.header(stamp, ''), status=statuses))

    def close(self) -> None:
        """Stop the pacing thread (called before the node is destroyed)."""
        self._stop.set()
        self._thread.join(timeout=2.0)


def _order_name(text: str) -> str:
    """Return the ``order`` (else ``id``) of a flight order's text, to acknowledge bad ones too."""
    try:
        data = load_strict(text) if isinstance(text, str) and len(text) <= 1 << 20 else None
    except ValueError as exc:
        data = getattr(exc, 'partial', None)
    if isinstance(data, dict):
        for key in ('order', 'id'):
            value = data.get(key)
            if (
                isinstance(value, (str, int))
                and not isinstance(value, bool)
                and str(value).isprintable()
            ):
                return str(value)[:128] or 'unknown'
    return 'unknown'


def _landed_text(position, time_of_flight: float) -> str:
    return (
        f'landed at x = {position[0]:.3f} m, y = {position[1]:.3f} m after {time_of_flight:.4f} s'
    )


def _warm_up() -> None:
    """Load the compiled kernels now, so that the first flight's ticks are not late."""
    from ..physics.precompile import compile_ahead

    compile_ahead()  # every kernel of the nodes and commands (compiled once, then loaded)
    flight = Flight.from_release(Release())
    flight.sample(0.0105)
    flight.sample(10.0)
    mb.odometry(flight.sample(10.0), mb.time_msg(0), FIELD_FRAME, BODY_FRAME)


def main(argv=None) -> int:
    return run_node(SimulatorNode, argv, 'simulator')


if __name__ == '__main__':
    raise SystemExit(main())
