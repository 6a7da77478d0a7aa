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
Planner node: a target in, the release that gets there (least wobble) out.

Requests: ``football/plan/request`` (std_msgs/String, the strict request language of release
requests: :func:`football_ros.requests.read_request`, keys of
:mod:`football_ros.planning.request`). Every request gets exactly one
``football/plan/response`` (diagnostic_msgs/DiagnosticStatus, name = the request id; the plan's
numbers as values) and a plan also its path on ``football/plan/path`` (nav_msgs/Path, frame
``frame_id``). ``execute: true`` also sends the plan as a release request on
``football/release/request`` under the id the answer's ``release_request_id`` gives (the plan's
own id, or ``plan-<node token>-<n>`` for a plan without a client id, whose made-up id the
release node would not take); the release node answers it on its own response topic.
``receiver: odom`` plans for the receiver last seen on the Odometry topic ``receiver_topic``
(pose and twist in ``field``; a TF frame name would need tf2, which the pip-installed ROS lacks).

Threads: the executor reads requests (strict parse, the fields) and queues them; a worker
plans (each plan bounded by the planner's flight budgets); a full queue is answered "busy" at
once.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import queue
import sys
import threading
import traceback

from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry, Path
from rclpy.node import Node
from std_msgs.msg import String

from . import messages as mb
from . import qos
from .inbox import lost_counter
from .params import declare_all, GUARD, ParamSpec
from .runner import run_node
from ..physics import compile_ahead
from ..physics.frames import FIELD_FRAME
from ..planning import arcs_summary, compare_arcs, hit_probability, plan, PlanError, Receiver
from ..planning.planner import warm_up
from ..planning.request import PlanRequest, read_plan_request
from ..requests import capped, MAX_REQUEST_BYTES, read_request, RequestError, RESERVED_ID

NODE_NAME = 'football_planner'
HARDWARE_ID = 'football_ros/planner'
MAX_PATH_POSES = 500

PARAMETERS = (
    ParamSpec('max_request_bytes', MAX_REQUEST_BYTES, 'Largest accepted request text [bytes]',
              (64, 1 << 20), guard=GUARD),
    ParamSpec('queue_depth', 16, 'Plan requests waiting for the worker at most; more are '
              'answered busy', (1, 1000), read_only=True),
    ParamSpec('hit_n', 1000, 'Balls flown for the hit probability unless a request says '
              '(0 = none)', (0, 100000), guard=GUARD),
    ParamSpec('frame_id', FIELD_FRAME, 'Frame of the path and of every point (field)',
              non_empty=True, guard=GUARD),
    ParamSpec('receiver_topic', '', "Odometry topic of a receiver ('' = none); requests "
              'with receiver: odom plan for its last pose and twist', read_only=True),
)


class PlannerNode(Node):
    """Answers plan requests once each, publishes the planned path, optionally throws."""

    PARAMETERS = PARAMETERS

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        declare_all(self, PARAMETERS)
        self.counts = {'received': 0, 'planned': 0, 'refused': 0, 'busy': 0, 'lost': 0}
        self._lock = threading.Lock()
        self._work: queue.Queue = queue.Queue(maxsize=self.queue_depth)
        self._receiver: Odometry | None = None
        self._release_ids = (f'plan-{os.urandom(3).hex()}-{n}' for n in itertools.count(1))
        self._responses = self.create_publisher(DiagnosticStatus, qos.PLAN_RESPONSE, qos.REQUEST)
        self._paths = self.create_publisher(Path, qos.PLAN_PATH, qos.PLAN_PATH_QOS)
        self._releases = self.create_publisher(String, qos.RELEASE_REQUEST, qos.REQUEST_WRITER)
        compile_ahead()
        warm_up()  # the planner's own kernels
        self.create_subscription(String, qos.PLAN_REQUEST, self._on_request, qos.REQUEST_INBOX,
                                 event_callbacks=lost_counter(self, self.counts, 'plan requests'))
        if self.receiver_topic:
            self.create_subscription(Odometry, self.receiver_topic, self._on_receiver, 10)
        sys.setswitchinterval(5e-4)
        self._stop = threading.Event()
        self._worker = threading.Thread(target=self._serve, name='football-planner-worker',
                                        daemon=True)
        self._worker.start()
        self.get_logger().info(
            f"ready: plan requests on '{self.resolve_topic_name(qos.PLAN_REQUEST)}', answers on "
            f"'{self.resolve_topic_name(qos.PLAN_RESPONSE)}'"
        )

    # --- executor thread ---------------------------------------------------------------------
    def _on_request(self, msg: String) -> None:
        self.counts['received'] += 1
        request_id = 'unknown'
        try:
            request_id, keys = read_request(msg.data, self.max_request_bytes)
            req = read_plan_request(keys)  # cheap: the fields, before the queue
        except RequestError as exc:
            self._refuse(exc.request_id, str(exc))
            return
        except PlanError as exc:
            self._refuse(request_id, str(exc), {'limit': exc.limit})
            return
        except Exception as exc:  # never let one request take the node down
            self._internal_error(request_id, exc)
            return
        try:
            self._work.put_nowait((request_id, req))
        except queue.Full:
            self.counts['busy'] += 1
            self._respond(request_id, 'ERROR',
                          f'busy: {self.queue_depth} plan requests are waiting; send it again '
                          'later', {'busy': True})

    def _on_receiver(self, msg: Odometry) -> None:
        with self._lock:
            self._receiver = msg

    # --- worker thread -----------------------------------------------------------------------
    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                request_id, req = self._work.get(timeout=0.05)
            except queue.Empty:
                continue
            try:
                self._plan(request_id, req)
            except Exception as exc:
                self._internal_error(request_id, exc)

    def _receiver_now(self) -> Receiver:
        with self._lock:
            msg = self._receiver
        if msg is None:
            raise PlanError('receiver: odom, but no receiver Odometry has arrived on '
                            f"'{self.receiver_topic or '(receiver_topic not set)'}'", 'receiver')
        if msg.header.frame_id not in ('', self.frame_id):
            raise PlanError(f"the receiver Odometry is in '{msg.header.frame_id[:40]}', not "
                            f"'{self.frame_id}'", 'receiver')
        p, v = msg.pose.pose.position, msg.twist.twist.linear
        stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        now = self.get_clock().now().nanoseconds * 1e-9
        age = stamp - now if stamp > 0.0 else 0.0
        return Receiver((p.x, p.y, p.z), (v.x, v.y, v.z), max(age, -30.0))

    def _plan(self, request_id: str, req: PlanRequest) -> None:
        try:
            if req.receiver_from_odometry:
                req.options['receiver'] = self._receiver_now()
            the_plan = plan(**req.options)
        except PlanError as exc:
            values = {'limit': exc.limit}
            if exc.closest is not None:
                values.update(zip(('closest_x', 'closest_y', 'closest_z'),
                                  (float(c) for c in exc.closest)))
            self._refuse(request_id, str(exc), values)
            return
        values = _flat(the_plan.to_mapping())
        level, note = 'OK', ''
        n = self.hit_n if req.hit_n is None else req.hit_n
        if n > 0:
            try:
                est = hit_probability(the_plan, req.sigmas, req.catch_radius, n)
                values.update(est.to_mapping())
            except PlanError as exc:
                values['hit_probability_note'] = str(exc)
            if req.compare_arcs and 'target' in req.options:
                skip = ('objective', 'arrival_time', 'arrival_window')
                options = {k: v for k, v in req.options.items() if k not in skip}
                target, base = options.pop('target'), options.pop('base')
                comparison = compare_arcs(target, base, req.sigmas, req.catch_radius,
                                          max(n, 100), **options)
                values.update(arcs_summary(comparison))
        if the_plan.warnings:
            level = 'WARN'
        if req.execute:
            if self._releases.get_subscription_count() == 0:
                level, note = 'WARN', '; not thrown: no release node is listening'
            else:
                release_id = self._release_id(request_id)
                request = dict(the_plan.release_mapping(), id=release_id)
                self._releases.publish(String(data=json.dumps(request)))
                values['release_request_id'] = release_id
                note = f"; sent to the release node as '{release_id}'"
        self._paths.publish(self._path(the_plan))
        self.counts['planned'] += 1
        r = the_plan.release
        self._respond(
            request_id,
            level,
            f'planned: {r.speed:.2f} m/s at {r.elevation_deg:.2f} deg elevation, '
            f'{r.azimuth_deg:.2f} deg azimuth, arrives after {the_plan.arrival_time:.3f} s '
            f'{the_plan.miss_m * 1000:.1f} mm from the target; {the_plan.sentence}{note}',
            values,
        )

    def _release_id(self, request_id: str) -> str:
        """Return the id a plan's release request goes under: the client's, else a fresh one."""
        return next(self._release_ids) if RESERVED_ID.fullmatch(request_id) else request_id

    def _path(self, the_plan) -> Path:
        stamp = self.get_clock().now().to_msg()
        header = mb.header(stamp, self.frame_id)
        points = the_plan.path_positions
        step = max(1, math.ceil(len(points) / MAX_PATH_POSES))
        chosen = list(points[::step])
        if (len(points) - 1) % step:
            chosen.append(points[-1])
        poses = []
        for p in chosen:
            pose = PoseStamped(header=header)
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = (
                float(p[0]), float(p[1]), float(p[2]))
            pose.pose.orientation.w = 1.0
            poses.append(pose)
        return Path(header=header, poses=poses)

    # --- answers -----------------------------------------------------------------------------
    def _refuse(self, request_id: str, reason: str, values: dict | None = None) -> None:
        self.counts['refused'] += 1
        self._respond(request_id, 'ERROR', f'refused: {capped(reason)}', values or {})

    def _internal_error(self, request_id: str, exc: Exception) -> None:
        self.get_logger().error(
            f"plan request '{request_id}': internal error\n{traceback.format_exc()}"
        )
        self._refuse(request_id, f'internal error ({type(exc).__name__}); the node logged the '
                     'details')

    def _respond(self, request_id: str, level: str, message: str, values: dict) -> None:
        status = mb.diagnostic_status(request_id, level, message, values, hardware_id=HARDWARE_ID)
        with self._lock:
            self._responses.publish(status)

    def close(self) -> None:
        """Stop the worker; answer what is still queued."""
        self._stop.set()
        self._worker.join(timeout=5.0)
        left = []
        while True:
            try:
                left.append(self._work.get_nowait()[0])
            except queue.Empty:
                break
        if self.context.ok():
            for request_id in left:
                self._refuse(request_id, 'the planner node is shutting down')
        print('[planner] {received} requests received: {planned} planned, {refused} refused, '
              '{busy} busy; {lost} lost on the way (DDS)'.format(**self.counts), file=sys.stderr,
              flush=True)


def _flat(mapping: dict) -> dict:
    """Return plan values as flat key-values: lists as x/y/z keys, nested mappings dotted."""
    out: dict = {}
    for key, value in mapping.items():
        if isinstance(value, dict):
            for k, v in value.items():
                out[f'{key}.{k}'] = v if not isinstance(v, (list, tuple)) else json.dumps(v)
        elif isinstance(value, (list, tuple)) and len(value) == 3 and key != 'warnings':
            out.update(zip((f'{key}_x', f'{key}_y', f'{key}_z'), value))
        elif isinstance(value, (list, tuple)):
            out[key] = '; '.join(map(str, value))
        elif isinstance(value, float) and not math.isfinite(value):
            out[key] = 'nan'
        else:
            out[key] = value
    return out


def main(argv=None) -> int:
    return run_node(PlannerNode, argv, 'planner')


if __name__ == '__main__':
    raise SystemExit(main())
