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
Release node: release conditions in, one accept/reject answer out, flight order to the simulator.

Requests: ``football/release/request`` (std_msgs/String, strict YAML/JSON mapping) or
``football/release/state`` (nav_msgs/Odometry, the ball's rigid-body state). Every request gets
exactly one ``football/release/response`` (diagnostic_msgs/DiagnosticStatus, name = the request
id). A valid release becomes a flight order on ``football/flight/order``; the answer waits for
the simulator's acknowledgement on ``football/flight/ack``, so OK means "the simulator has
started this flight", and a refusal or silence is an ERROR. Silence is judged in wall time:
after ``ack_timeout`` when no simulator reads the flight orders any more, else (a simulator
slowed down by a loaded machine) after ``ack_patience``.

Threads: the executor thread reads requests cheaply (strict parse, field checks) and queues them;
a worker thread predicts the flight and sends the order; acknowledgements come back on the
executor. A request that finds the queue full is answered "busy" at once. Contract: msg_docs/.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
import os
import queue
import sys
import threading
import time
import traceback

from diagnostic_msgs.msg import DiagnosticStatus
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.node import Node
from std_msgs.msg import String

from . import messages as mb
from . import qos
from .inbox import lost_counter
from .logs import throttled
from .params import declare_all, GUARD, ParamSpec
from .runner import run_node
from ..physics import compile_ahead, Flight, InitialState, PRESETS, ReleaseError
from ..physics.flight import flight_summary
from ..physics.frames import BODY_FRAME, FIELD_FRAME, quaternion_to_matrix
from ..physics.release import MODELS, MOMENT_CURVES
from ..requests import (
    brief,
    capped,
    FlightOrder,
    MAX_REQUEST_BYTES,
    read_request,
    release_from_request,
    RequestError,
)

NODE_NAME = 'football_release'
HARDWARE_ID = 'football_ros/release'
PREDICTION_HORIZON_S = 60.0
MAX_PENDING = 64
"""Orders waiting for the simulator's acknowledgement at most (more: answered 'busy')."""
GRAPH_CACHE_S = 0.5
"""How long the set of matched simulators is reused before the graph is asked again [s]."""
GRAPH_REFRESH_S = 0.1
"""Earliest re-read of the graph for an unknown sender after the last read [s]."""
MAX_NAMED = 16
"""Participants named in warnings at most (each once)."""
LOG_LINES_PER_S = 50
"""Answers logged per second at most; under a flood the rest are counted in the next line."""


class LogBudget:
    """At most ``per_second`` lines in each wall-clock second; counts the lines it refused."""

    def __init__(self, per_second: int, clock=time.monotonic) -> None:
        self.per_second, self._clock = per_second, clock
        self._window, self._used, self.dropped = -1, 0, 0

    def take(self) -> tuple[bool, int]:
        """Return (may log now, lines refused since the last allowed one)."""
        window = int(self._clock())
        if window != self._window:
            self._window, self._used = window, 0
        if self._used >= self.per_second:
            self.dropped += 1
            return False, 0
        self._used += 1
        dropped, self.dropped = self.dropped, 0
        return True, dropped


def node_fqn(info) -> str:
    """Fully qualified node name of a TopicEndpointInfo: '/ns/name' ('/name' at the root)."""
    namespace = info.node_namespace.rstrip('/')
    return f'{namespace}/{info.node_name}'


def prediction(flight: Flight) -> dict[str, object]:
    """Linear-theory numbers and the headless flight's landing, as response values."""
    m = flight.modes
    trajectory = flight.simulate(rate=100.0, duration=PREDICTION_HORIZON_S)
    values: dict[str, object] = {
        'omega_fast': m.omega_fast,
        'omega_slow': m.omega_slow,
        'critical_spin_rpm': m.critical_spin_rpm,
        'equilibrium_sideslip': m.equilibrium_sideslip,
        'stable': m.stable,
        'm_alpha': m.m_alpha,
        'h1': m.h1,
        'gyroscopic_stability_factor': m.gyroscopic_stability_factor,
    }
    values.update(flight_summary(trajectory.times, trajectory.positions, trajectory.landed))
    if trajectory.landed:
        values.update(
            {
                'landing_x': float(trajectory.positions[-1, 0]),
                'landing_y': float(trajectory.positions[-1, 1]),
            }
        )
    return values


@dataclass
class _Work:
    """A request read, waiting for the worker: its id and its keys or its flight order."""

    request_id: str
    order: FlightOrder | None = None
    keys: dict | None = None


@dataclass
class _Pending:
    """An order sent to the simulator, waiting for its acknowledgement."""

    request_id: str
    sent: float  # time.monotonic() [s]
    deadline: float  # time.monotonic() of the next look [s]
    text: str  # the accepted answer's sentence
    stable: bool
    values: dict


PARAMETERS = (
    ParamSpec(
        'max_request_bytes',
        MAX_REQUEST_BYTES,
        'Largest accepted request text [bytes]',
        (64, 1 << 20),
        guard=GUARD,
    ),
    ParamSpec(
        'integration_step',
        0.001,
        'Integration step of the landing prediction [s]',
        (5e-4, 0.01),
        guard=GUARD,
    ),
    ParamSpec(
        'ack_timeout',
        1.0,
        "Wall time to wait for the simulator's acknowledgement once no simulator reads the "
        'flight orders [s]',
        (0.1, 10.0),
        guard=GUARD,
    ),
    ParamSpec(
        'ack_patience',
        10.0,
        "Wall time to wait for the simulator's acknowledgement while a simulator still reads "
        'the flight orders (a loaded machine) [s]',
        (0.1, 600.0),
        guard=GUARD,
    ),
    ParamSpec(
        'queue_depth',
        64,
        'Requests waiting for the worker at most; more are answered busy',
        (1, 1000),
        read_only=True,
    ),
    ParamSpec(
        'state_ball',
        'american',
        'Ball preset of releases given as an Odometry on football/release/state',
        choices=tuple(PRESETS),
        guard=GUARD,
    ),
    ParamSpec('state_model', 'paper', 'Model of Odometry releases', choices=MODELS, guard=GUARD),
    ParamSpec(
        'state_moment',
        'linear',
        'Moment curve of Odometry releases',
        choices=MOMENT_CURVES,
        guard=GUARD,
    ),
    ParamSpec(
        'body_frame_id',
        BODY_FRAME,
        'Body frame an Odometry release may give its twist in',
        non_empty=True,
        guard=GUARD,
    ),
)


class ReleaseNode(Node):
    """Validates release requests, orders accepted flights and answers each request once."""

    PARAMETERS = PARAMETERS

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        declare_all(self, PARAMETERS)
        self._token = os.urandom(3).hex()  # order ids unique across release nodes on a domain
        self._sequence = 0
        self._lock = threading.Lock()  # pending orders and the response publisher
        self._pending: dict[str, _Pending] = {}
        self._other_simulators: set[str] = set()
        self._strangers: set[str] = set()  # ack writers named in a warning (bounded)
        self._simulators: tuple[float, frozenset[str]] = (-math.inf, frozenset())
        self._log_budget = LogBudget(LOG_LINES_PER_S)
        self._work: queue.Queue[_Work] = queue.Queue(maxsize=self.queue_depth)
        self.counts = {
            'received': 0, 'accepted': 0, 'rejected': 0, 'busy': 0, 'ignored_acks': 0, 'lost': 0
        }
        self._responses = self.create_publisher(
            DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST
        )
        self._orders = self.create_publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
        compile_ahead()  # every kernel loaded (compiled on a cold cache) before 'ready'
        self.create_subscription(DiagnosticStatus, qos.FLIGHT_ACK, self._on_ack, qos.REQUEST)
        lost = lost_counter(self, self.counts, 'requests')
        self.create_subscription(
            String, qos.RELEASE_REQUEST, self._on_request, qos.REQUEST_INBOX, event_callbacks=lost
        )
        self.create_subscription(
            Odometry, qos.RELEASE_STATE, self._on_state, qos.REQUEST_INBOX, event_callbacks=lost
        )
        # The executor takes the GIL back from the worker within 0.5 ms (default 5 ms).
        sys.setswitchinterval(5e-4)
        self._stop = threading.Event()
        self._worker = threading.Thread(
            target=self._serve, name='football-release-worker', daemon=True
        )
        self._worker.start()
        self.get_logger().info(
            f"ready: requests on '{self.resolve_topic_name(qos.RELEASE_REQUEST)}' and "
            f"'{self.resolve_topic_name(qos.RELEASE_STATE)}', answers on "
            f"'{self.resolve_topic_name(qos.RELEASE_RESPONSE)}'"
        )

    # --- executor thread: read, check, queue -------------------------------------------------
    def _on_request(self, msg: String) -> None:
        self.counts['received'] += 1
        try:
            request_id, keys = read_request(msg.data, self.max_request_bytes)
        except RequestError as exc:
            self._reject(exc.request_id, str(exc))
            return
        except Exception as exc:  # never let one request take the node down
            self._internal_error('unknown', exc)
            return
        self._enqueue(_Work(request_id, keys=keys))

    def _on_state(self, msg: Odometry) -> None:
        self.counts['received'] += 1
        stamp = msg.header.stamp
        request_id = f'state:{stamp.sec}.{stamp.nanosec:09d}'
        try:
            order = self._order_from_odometry(request_id, msg)
        except (ReleaseError, ValueError) as exc:
            self._reject(request_id, str(exc))
            return
        except Exception as exc:
            self._internal_error(request_id, exc)
            return
        self._enqueue(_Work(request_id, order=order))

    def _order_from_odometry(self, request_id: str, msg: Odometry) -> FlightOrder:
        """Return the flight order an Odometry of the ball means (twist per its convention)."""
        frame, child = msg.header.frame_id, msg.child_frame_id
        if frame not in ('', FIELD_FRAME):
            raise ReleaseError(
                f"header.frame_id must be '{FIELD_FRAME}' (or empty), got {brief(frame)}"
            )
        if child not in ('', self.body_frame_id, FIELD_FRAME):
            raise ReleaseError(
                f"child_frame_id must be the ball's body frame '{self.body_frame_id}' "
                f"(twist in the body frame) or '{FIELD_FRAME}' (twist in the field), "
                f'got {brief(child)}'
            )
        pose, twist = msg.pose.pose, msg.twist.twist
        quat = np.array(
            [pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w]
        )
        linear, angular = mb.vector_of(twist.linear), mb.vector_of(twist.angular)
        if child != FIELD_FRAME:  # the body frame's components: rotate into the field
            if not np.all(np.isfinite(quat)) or not np.linalg.norm(quat) > 0.0:
                raise ReleaseError(
                    f'orientation must be 4 finite numbers of a unit quaternion, got {list(quat)}'
                )
            rotation = quaternion_to_matrix(quat / np.linalg.norm(quat))
            linear, angular = rotation @ linear, rotation @ angular
        initial = InitialState.from_rigid_body(mb.vector_of(pose.position), linear, quat, angular)
        return FlightOrder(
            request_id, self.state_ball, {}, self.state_model, self.state_moment, initial
        )

    def _enqueue(self, work: _Work) -> None:
        try:
            self._work.put_nowait(work)
        except queue.Full:
            self.counts['busy'] += 1
            self._respond(
                work.request_id,
                'ERROR',
                f'busy: {self.queue_depth} requests are waiting; send it again later',
                {'busy': True},
                log=False,
            )

    # --- worker thread: predict, order, expire ---------------------------------------------
    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                work = self._work.get(timeout=0.05)
            except queue.Empty:
                work = None
            if work is not None:
                try:
                    self._order(work)
                except Exception as exc:
                    self._internal_error(work.request_id, exc)
            self._expire()

    def _order(self, work: _Work) -> None:
        """Validate the order as the simulator will, predict it, send it and wait for the ack."""
        with self._lock:
            self._sequence += 1
            order_id = f'{self._token}-{self._sequence}'
            busy = len(self._pending) >= MAX_PENDING
        if busy:
            self.counts['busy'] += 1
            self._respond(
                work.request_id,
                'ERROR',
                f'busy: {MAX_PENDING} flight orders await the '
                "simulator's acknowledgement; send it again later",
                {'busy': True},
                log=False,
            )
            return
        order = work.order
        try:
            if order is None:
                release = release_from_request(work.request_id, work.keys)
                order = FlightOrder.from_release(work.request_id, release, order_id)
            else:
                order = replace(order, order_id=order_id)
            text = order.to_json()  # the order is valid by construction: the simulator's rules
            flight = order.flight(self.integration_step)
        except ValueError as exc:
            self._reject(work.request_id, str(exc))
            return
        values = prediction(flight)
        if self._orders.get_subscription_count() == 0:
            self._reject(
                work.request_id,
                'valid release, but no simulator is listening on '
                f"'{self.resolve_topic_name(qos.FLIGHT_ORDER)}' (start one: "
                "'ros2 run football_ros simulator' or 'football-ros simulator')",
                values,
            )
            return
        tof = values['time_of_flight']
        stable = flight.modes.stable
        sentence = (
            f'{order.ball_name} at {np.linalg.norm(order.initial.velocity):.2f} m/s; '
            + (
                f'lands at {values["range"]:.2f} m after {tof:.3f} s'
                if not math.isnan(tof)
                else f'still flying after {PREDICTION_HORIZON_S:g} s'
            )
            + (
                ''
                if stable
                else '; WARNING: gyroscopically unstable '
                f'(spin below {values["critical_spin_rpm"]:.0f} rpm), the ball will tumble'
            )
        )
        now = time.monotonic()
        with self._lock:
            self._pending[order_id] = _Pending(
                work.request_id, now, now + self.ack_timeout, sentence, stable, values
            )
        self._orders.publish(String(data=text))

    def _expire(self) -> None:
        """Answer the orders whose wait is over; wait on while a simulator reads the orders."""
        now = time.monotonic()
        with self._lock:
            due = [p for p in self._pending.values() if p.deadline <= now]
        if not due:
            return
        listening = self._orders.get_subscription_count() > 0
        patience = max(self.ack_patience, self.ack_timeout)
        late = []
        with self._lock:
            for oid, p in list(self._pending.items()):
                if p.deadline > now:
                    continue
                if listening and now - p.sent < patience:
                    p.deadline = min(now + self.ack_timeout, p.sent + patience)
                else:
                    late.append(self._pending.pop(oid))
        for pending in late:
            self._reject(
                pending.request_id,
                f'no simulator acknowledged the flight order within {now - pending.sent:.3g} s '
                + (
                    '(a simulator reads the orders but did not answer)'
                    if listening
                    else '(no simulator reads the flight orders: is the simulator running?)'
                ),
                pending.values,
            )

    # --- executor thread: acknowledgements ---------------------------------------------------
    def matched_simulators(self, refresh: bool = False) -> frozenset[str]:
        """
        Return the fully qualified names of the nodes that may acknowledge our orders.

        A matched simulator reads ``football/flight/order`` and writes ``football/flight/ack``
        (the graph, as ``ros2 topic info -v`` shows it). The graph is read at most every
        GRAPH_CACHE_S seconds, or GRAPH_REFRESH_S after the last read with ``refresh``. Ack
        writers that read no orders are named in one warning each.
        """
        now = time.monotonic()
        read_at, names = self._simulators
        if now - read_at < (GRAPH_REFRESH_S if refresh else GRAPH_CACHE_S):
            return names
        order_topic = self.resolve_topic_name(qos.FLIGHT_ORDER)
        ack_topic = self.resolve_topic_name(qos.FLIGHT_ACK)
        readers = {node_fqn(i) for i in self.get_subscriptions_info_by_topic(order_topic)}
        writers = {node_fqn(i) for i in self.get_publishers_info_by_topic(ack_topic)}
        names = frozenset(readers & writers)
        self._simulators = (now, names)
        for stranger in sorted(writers - readers):
            if stranger not in self._strangers and len(self._strangers) < MAX_NAMED:
                self._strangers.add(stranger)
                self.get_logger().warning(
                    f"'{capped(stranger, 120)}' publishes on '{ack_topic}' but reads no flight "
                    'orders: '
                    'its acknowledgements are not taken'
                )
        return names

    def _on_ack(self, msg: DiagnosticStatus) -> None:
        try:
            simulator = msg.hardware_id[:120]
            with self._lock:
                known = msg.name in self._pending
            if known and simulator not in self.matched_simulators(refresh=False):
                if simulator not in self.matched_simulators(refresh=True):
                    self.counts['ignored_acks'] += 1
                    throttled(
                        self.get_logger(), 'warning',
                        f"acknowledgement of flight order '{msg.name[:40]}' ignored: it names "
                        f"'{capped(simulator, 120)}', which is not a simulator this node matched "
                        '(a node reading the flight orders and writing the acknowledgements); '
                        'another participant sent it',
                        1.0,
                    )
                    return
            try:
                ack_level = mb.level_of(msg)
            except KeyError:  # a level byte no simulator sends
                self.counts['ignored_acks'] += 1
                throttled(
                    self.get_logger(), 'warning',
                    f"acknowledgement of '{msg.name[:40]}' ignored: unknown level "
                    f'{bytes(msg.level)[:1]!r} (another participant sent it)',
                    1.0,
                )
                return
            with self._lock:
                pending = self._pending.pop(msg.name, None)
            if pending is None:
                if (
                    msg.name.startswith(self._token + '-')
                    and simulator not in self._other_simulators
                    and len(self._other_simulators) < MAX_NAMED
                ):
                    self._other_simulators.add(simulator)
                    self.get_logger().warning(
                        f"flight order '{msg.name[:40]}' was acknowledged again, by "
                        f"'{simulator}': more than one simulator listens to the flight orders "
                        '(or its answer came too late)'
                    )
                return
            values = dict(pending.values, simulator=simulator)
            if ack_level == 'ERROR':
                self._reject(
                    pending.request_id,
                    f'the simulator refused the flight: {capped(msg.message)}',
                    values,
                )
                return
            level = 'OK' if pending.stable else 'WARN'
            self.counts['accepted'] += 1
            self._respond(pending.request_id, level, f'accepted: {pending.text}', values)
        except Exception as exc:
            self._internal_error(msg.name[:40] or 'unknown', exc)

    # --- answers -----------------------------------------------------------------------------
    def _reject(self, request_id: str, reason: str, values: dict | None = None) -> None:
        self.counts['rejected'] += 1
        self._respond(request_id, 'ERROR', f'rejected: {capped(reason)}', values or {})

    def _internal_error(self, request_id: str, exc: Exception) -> None:
        if self._log_budget.take()[0]:
            details = capped(traceback.format_exc(), 4000)
            self.get_logger().error(f"request '{request_id}': internal error\n{details}")
        self._reject(
            request_id, f'internal error ({type(exc).__name__}); the node logged the details'
        )

    def _respond(
        self, request_id: str, level: str, message: str, values: dict, log: bool = True
    ) -> None:
        allowed, dropped = self._log_budget.take() if log else (False, 0)
        if dropped:
            message_log = f'{message} ({dropped} answers before it were not logged: flood)'
        else:
            message_log = message
        if allowed and level == 'OK':
            self.get_logger().info(f"request '{request_id}' {message_log}")
        elif allowed:  # rclpy fixes one severity per call site
            self.get_logger().warning(f"request '{request_id}' {message_log}")
        status = mb.diagnostic_status(request_id, level, message, values, hardware_id=HARDWARE_ID)
        with self._lock:
            self._responses.publish(status)

    def close(self) -> None:
        """Stop the worker; answer what is still queued or awaiting an acknowledgement."""
        self._stop.set()
        self._worker.join(timeout=2.0)
        left = []
        while True:
            try:
                left.append(self._work.get_nowait().request_id)
            except queue.Empty:
                break
        with self._lock:
            left += [p.request_id for p in self._pending.values()]
            self._pending.clear()
        if self.context.ok():
            for request_id in left:
                self._reject(request_id, 'the release node is shutting down')
        print(
            '[release] {received} requests received: {accepted} flown, {rejected} refused, '
            '{busy} busy; {lost} lost on the way (DDS)'.format(**self.counts),
            file=sys.stderr,
            flush=True,
        )


def main(argv=None) -> int:
    return run_node(ReleaseNode, argv, 'release')


if __name__ == '__main__':
    raise SystemExit(main())
