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
same stamp. After publishing, a tick integrates the next tick's sample, so that the next tick
publishes at its deadline whatever the integration costs (in place instead when the flight
changed meanwhile or the simulated camera is on). After the landing the landed state is
republished at ``hold_rate`` (0 = never). ``thread_priority`` > 0 puts the pacing thread on
SCHED_FIFO, so that other work of the machine does not make ticks late (:func:`fifo_priority`),
and the executor thread one priority below it: a handler holding the GIL must not be preempted
by ordinary work while the pacer waits for it (a priority inversion).

Threads: the pacing thread is the only one that integrates and publishes state, markers, /clock
and /diagnostics; the executor thread serves orders, services, parameters and a 1 Hz check for
other publishers of the state topics. The node's lock is held only to read or swap the flight
bookkeeping, never around the integration, so services answer while a tick integrates.

Bounded work: real_time_factor / integration_step (RK4 steps per wall second) is at most
``MAX_STEPS_PER_SECOND``, a trail marker carries at most ``messages.MAX_TRAIL_POINTS`` points
and at most ``MAX_EVENTS`` events wait for /diagnostics.

Guard: a sample with a non-finite value, a speed or distance far past what the release allows,
an exception while integrating, or no landing within ``MAX_FLIGHT_S`` ends the flight with an
ERROR event; nothing non-finite is published. The flight run itself (time flown, guard, data
range, landing, events) is ROS-free: :mod:`football_ros.simulation.world`.
Topics, frames, units and QoS: msg_docs/.
"""

from __future__ import annotations

import collections
import gc
import math
import os
import sys
import threading
import time
import traceback

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

from . import messages as mb
from . import qos
from .cameras import CameraRigPublisher
from .logs import throttled
from .observation_hook import ObservationHook, PARAMETERS as OBSERVATION_PARAMETERS
from .params import declare_all, ParamSpec
from .quiet import QuietNode
from .runner import EXECUTOR_TYPES, run_node

try:  # the system package on a Jazzy install; pip_ros/simulation_interfaces on the pip ROS
    from .simulation_services import SimulationServices
except ImportError:  # pragma: no cover - no simulation_interfaces: the node runs without them
    SimulationServices = None
from ..estimation.rig import load_rig
from ..physics import Release
from ..physics.flight import Flight
from ..physics.frames import BODY_FRAME, FIELD_FRAME
from ..physics.release import RPM
from ..requests import capped, FlightOrder, OrderError
from ..simulation.core import Frame, PAUSED, PLAYING, Simulation, STATE_NAMES, STOPPED
from ..simulation.world import (  # noqa: F401  (MAX_*: the limits, documented here too)
    DEFAULT_ENTITY,
    Entity,
    FlightRun,
    landed_text,
    MAX_EVENTS,
    MAX_FLIGHT_S,
    ShownSample,
    World,
)

NODE_NAME = 'football_simulator'
MODEL_CHOICES = ('release', 'paper', 'full')
MAX_CATCH_UP_S = 1.0
"""A stall longer than this is not replayed: its ticks are skipped (and counted)."""
TICK_GUARD_S = 0.002
"""A handler that would start within this of the next tick waits for the tick (TickGate)."""
MAX_STEPS_PER_SECOND = 2.0e5
"""Largest real_time_factor / integration_step [RK4 steps per wall second] (about 0.2 s of CPU
per wall second at 0.85 us a step); larger combinations are refused (parameter callback)."""
RIVAL_CHECK_PERIOD_S = 1.0
SUBSCRIBER_CHECKS_PER_TICK = 10
"""Spawned entities whose topics' subscribers are counted per tick, in turn (each count is an
rmw graph query; a topic nobody subscribes to is not published)."""
LOG_THROTTLE_S = 0.1
"""Lines a client can trigger at will (pause, reset, orders) are logged at most this often
each; every event still reaches /diagnostics (bounded by MAX_EVENTS)."""

PARAMETERS = (
    ParamSpec(
        'publish_rate',
        100.0,
        'State messages per second of wall time [Hz]',
        (1.0, 2000.0),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'integration_step',
        0.001,
        'Fixed RK4 step of the integrator [s] (next flight); real_time_factor / '
        f'integration_step <= {MAX_STEPS_PER_SECOND:g}',
        (1e-5, 0.01),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'real_time_factor',
        1.0,
        'Simulated seconds per wall second; real_time_factor / '
        f'integration_step <= {MAX_STEPS_PER_SECOND:g}',
        (0.01, 100.0),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'publish_clock',
        False,
        'Publish the global /clock (simulated time) and stamp every message with it',
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'frame_id',
        FIELD_FRAME,
        'World frame (REP-103: x downfield, z up)',
        non_empty=True,
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'child_frame_id',
        BODY_FRAME,
        'Body frame of the ball (x = spin axis toward the leading nose)',
        non_empty=True,
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'marker_rate',
        30.0,
        'RViz markers per second [Hz], 0 = off',
        (0.0, 200.0),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'trail_length',
        500,
        'Positions kept for the trail marker (one per marker); a '
        f'marker carries at most {mb.MAX_TRAIL_POINTS} of them, evenly spaced',
        (0, 100000),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'hold_rate',
        1.0,
        'Rate at which the landed state is republished [Hz], 0 = never',
        (0.0, 100.0),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'diagnostics_rate',
        1.0,
        'Periodic /diagnostics [Hz]',
        (0.1, 100.0),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'thread_priority',
        0,
        'Scheduling of the pacing thread: 0 = the normal scheduler; 1..99 = SCHED_FIFO at this '
        'real-time priority, the executor thread one below (as the thread_priority of the '
        'ros2_control manager; needs an rtprio limit or CAP_SYS_NICE, else a warning and the '
        'normal scheduler)',
        (0, 99),
        read_only=True,
    ),
    ParamSpec(
        'executor_type',
        'events',
        "Executor of the services, the action and the parameters: 'events' "
        '(rclpy.experimental.EventsExecutor: C++ dispatch, the cheaper per call; the other where '
        "rclpy lacks it) or 'single_threaded' (rclpy's SingleThreadedExecutor)",
        choices=EXECUTOR_TYPES,
        read_only=True,
    ),
    ParamSpec(
        'model',
        'release',
        "Equations of motion: 'release' (as each release asks), 'paper' or 'full'",
        choices=MODEL_CHOICES,
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'max_entities',
        100,
        'Most entities (balls) in the world, the default one included; SpawnEntity past it is '
        'refused',
        (1, 1000),
        guard='allow_reconfigure',
    ),
    ParamSpec(
        'root_services',
        False,
        'Also offer the simulation_interfaces services and action at root names '
        '(/spawn_entity, /step_simulation, ...; as Isaac Sim and O3DE name them), besides '
        '~/<name>',
        read_only=True,
    ),
    ParamSpec(
        'goal_result_timeout',
        900.0,
        "How long a finished SimulateSteps goal's result is kept for its client [s] (rclpy's "
        'default). Every goal status message lists every goal kept, so at hundreds of goals a '
        'second a goal costs more the more goals this window holds: shorten it (e.g. 5) when '
        'every client asks for its result as soon as its goal is accepted, as ros2 action '
        'send_goal does (a result asked for later is gone: status UNKNOWN)',
        (0.5, 3600.0),
        read_only=True,
    ),
    ParamSpec(
        'camera_rig',
        '',
        "Camera rig file (YAML, config/rig_*.yaml): each camera's CameraInfo and ball "
        "detections on football/camera/<name>/..., '' = none",
        read_only=True,
    ),
)
PUBLISH_TF = ParamSpec(
    'publish_tf',
    mb.TFMessage is not None,
    'Publish the ball on /tf (frame_id -> child_frame_id)',
    guard='allow_reconfigure',
)


def fifo_priority(priority: int, tid: int = 0) -> str | None:
    """
    Put thread ``tid`` (0: this one) on SCHED_FIFO at ``priority`` (1..99); return why not.

    A real-time thread wakes at its deadline ahead of every normal thread of the machine (a
    pacing loop on the normal scheduler is late by whole periods whenever the kernel runs
    something else first: bench/entities_benchmark.py measures both).
    """
    try:
        # Threads it starts later (e.g. the executor's timer thread) stay on the normal scheduler.
        policy = os.SCHED_FIFO | getattr(os, 'SCHED_RESET_ON_FORK', 0)
        os.sched_setscheduler(tid, policy, os.sched_param(priority))
    except (OSError, AttributeError) as exc:  # EPERM without rtprio; no SCHED_FIFO off Linux
        return str(exc)
    return None


class TickGate:
    """
    The pacing thread's right of way over the executor's handlers, in one process.

    A handler holds the GIL (and often the simulation's lock) while it runs; if the OS preempts
    it then, for other work of the machine, the pacer that wakes for its tick waits for the
    preempted handler: a late tick that a loop alone in its process would not have. A handler
    that would start within ``guard_s`` of the next tick waits instead (GIL released) until
    the pacer announces its next deadline (at most one period), so at a tick's deadline the
    executor holds nothing the tick needs unless a handler outruns the guard. A handler waits
    at most the guard and one tick; lock-step calls (StepSimulation, SimulateSteps) never wait
    (their ticks, paused, have nothing to be late for).
    """

    def __init__(self, guard_s: float) -> None:
        self._cond = threading.Condition()
        self._due_ns: int | None = None  # monotonic ns of the next tick; None: not pacing
        self._period_ns = 0
        self._guard_ns = int(guard_s * 1e9)

    def announce(self, due_ns: int | None, period_ns: int = 0) -> None:
        """Pacer: the next tick is due at ``due_ns`` (monotonic ns; None: pacing stopped)."""
        with self._cond:
            self._due_ns, self._period_ns = due_ns, period_ns
            self._cond.notify_all()

    def wait_clear(self) -> None:
        """Executor: return at once unless a tick is due within the guard, else after it."""
        with self._cond:
            due = self._due_ns
            if due is None:
                return
            ahead = due - time.monotonic_ns()
            if ahead > self._guard_ns or ahead < -self._period_ns:
                return  # no tick due soon (or the pacer is stuck: never wait on it)
            self._cond.wait_for(lambda: self._due_ns != due,
                                (ahead + self._period_ns) * 1e-9)


def check_parameters(values: dict, flight_step: float | None = None) -> str | None:
    """
    Return the reason a combination of parameter values is refused, or None.

    The rows' own rules (ranges, choices, non-empty frames) are the table's
    (:func:`~football_ros.nodes.params.declare_all`); this is the rule that ties two
    parameters. ``flight_step``: the step [s] of the flight in the air, if any.
    """
    step = min(values['integration_step'], flight_step or math.inf)
    rate = values['real_time_factor'] / step
    if rate > MAX_STEPS_PER_SECOND:
        return (
            f'real_time_factor {values["real_time_factor"]:g} with a {step:g} s step needs '
            f'{rate:.3g} RK4 steps per second, more than the {MAX_STEPS_PER_SECOND:g} a '
            'real-time tick allows: lower real_time_factor or raise integration_step'
        )
    return None


class SimulatorNode(QuietNode):
    """
    Simulator node: the ball in flight, paced in real time.

    Publishes pose, odometry, spin axis, alpha/beta (and their linear prediction), markers and
    diagnostics of the ball in flight, paced in real time.
    """

    PARAMETERS = PARAMETERS + (PUBLISH_TF,) + OBSERVATION_PARAMETERS

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        declare_all(self, PARAMETERS)
        reason = check_parameters({spec.name: getattr(self, spec.name) for spec in PARAMETERS})
        if reason:
            raise ValueError(reason)
        self._use_sim_time = bool(self.get_parameter('use_sim_time').value)
        # --- TF hook: the ball as the frame child_frame_id in frame_id on /tf ---
        self.publish_tf = PUBLISH_TF.declare(self)
        self._tf_pub = (
            None
            if mb.TFMessage is None
            else self.create_publisher(mb.TFMessage, qos.TF, qos.TF_QOS)
        )
        self._tf_last = (None, -1)  # (publish_clock, stamp ns) of the last transform sent
        self._observation = ObservationHook(self)  # simulated camera: observation_* (tracker)
        self._rig = (  # camera rig: CameraInfo and Detection2DArray per camera (cameras.py)
            CameraRigPublisher(self, load_rig(self.camera_rig), self.frame_id)
            if self.camera_rig else None
        )
        self.add_on_set_parameters_callback(self._on_parameters)
        self.diagnostic_name = f'football_ros: {self.get_fully_qualified_name()}'
        self.hardware_id = f'football_ros{self.get_fully_qualified_name()}'

        self._pubs = {
            qos.POSE: self.create_publisher(PoseStamped, qos.POSE, qos.STATE),
            qos.ODOM: self.create_publisher(Odometry, qos.ODOM, qos.STATE),
            qos.SPIN_AXIS: self.create_publisher(Vector3Stamped, qos.SPIN_AXIS, qos.STATE),
            qos.AERO_ANGLES: self.create_publisher(Vector3Stamped, qos.AERO_ANGLES, qos.STATE),
            qos.AERO_ANGLES_LINEAR: self.create_publisher(
                Vector3Stamped, qos.AERO_ANGLES_LINEAR, qos.STATE
            ),
            qos.AERO_ANGLES_QUASI_STEADY: self.create_publisher(
                Vector3Stamped, qos.AERO_ANGLES_QUASI_STEADY, qos.STATE
            ),
        }
        self._markers_pub = self.create_publisher(MarkerArray, qos.MARKERS, qos.MARKERS_QOS)
        self._diag_pub = self.create_publisher(
            DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS
        )
        self._clock_pub = self.create_publisher(Clock, qos.CLOCK, qos.CLOCK_QOS)
        self._ack_pub = self.create_publisher(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
        self.create_subscription(String, qos.FLIGHT_ORDER, self._on_order, qos.ORDER)
        self.create_service(Trigger, qos.RESET_SERVICE, self._on_reset,
                            qos_profile=qos.service_qos())
        self.create_service(SetBool, qos.PAUSE_SERVICE, self._on_pause,
                            qos_profile=qos.service_qos())
        self._state_msgs = mb.StateMessages()
        self._clock_msg = Clock()

        self.sim = Simulation(self.max_entities, self.integration_step)
        self.tick_gate = TickGate(TICK_GUARD_S)  # the pacer's right of way over the handlers
        self._tf = mb.TransformBatch()
        # name -> pose and odom publishers, EntityMessages, [spare, pose wanted, odom wanted]
        self._entity_pubs: dict[str, tuple] = {}
        self._wanted = np.zeros(0, dtype=bool)  # row -> somebody subscribes to its topics
        self._check_row = 0  # the last row whose subscribers were counted
        self.stats = {'ticks': 0, 'overruns': 0, 'skipped': 0, 'max_late_ms': 0.0}
        self._overruns_reported = 0
        self._rivals: tuple[str, ...] = ()
        self._sim_services = None
        if SimulationServices is not None:
            self._sim_services = SimulationServices(self, self.root_services)
        else:  # pragma: no cover - a ROS without simulation_interfaces
            self.get_logger().warning(
                'simulation_interfaces is not installed: no spawn/step/... services'
            )
        self._last_error_log = 0.0
        self.create_timer(RIVAL_CHECK_PERIOD_S, self._check_rivals)
        _warm_up()
        gc.freeze()  # start-up objects leave the collector's generations: shorter GC pauses
        sys.setswitchinterval(1e-4)  # the pacer gets the GIL within 0.1 ms (default: 5 ms)
        self._stop = threading.Event()
        self._scheduled = threading.Event()
        self._scheduling = 'normal scheduler'
        self._executor_tid = threading.get_native_id()  # the runner spins in this thread
        self._thread = threading.Thread(target=self._pace, name='football-pacer', daemon=True)
        self._thread.start()
        self._scheduled.wait(5.0)
        self.get_logger().info(
            f'ready: {self.publish_rate:g} Hz, step {self.integration_step:g} s, real-time factor '
            f'{self.real_time_factor:g}, pacing on the {self._scheduling}; waiting for flights on '
            f"'{self.resolve_topic_name(qos.FLIGHT_ORDER)}'"
        )

    # --- parameters, services, orders (executor thread) --------------------------------------
    def _on_parameters(self, params) -> SetParametersResult:
        """Check the whole new combination first (ranges: the descriptors), then apply it."""
        values = {spec.name: getattr(self, spec.name) for spec in PARAMETERS}
        values.update({p.name: p.value for p in params if p.name in values})
        run = self._run
        flying = run is not None and run.flying
        reason = check_parameters(values, run.flight.step if flying else None)
        if reason:
            return SetParametersResult(successful=False, reason=reason)
        for p in params:  # the hooks' parameters (publish_tf, observation_*) included
            if p.name == 'use_sim_time':
                self._use_sim_time = bool(p.value)
            else:
                setattr(self, p.name, p.value)
        self.sim.max_entities = int(self.max_entities)
        self.sim.step = float(self.integration_step)
        self.sim.changed.set()  # a resting pacer takes the new values at once
        return SetParametersResult(successful=True)

    @property
    def _run(self) -> FlightRun | None:
        """Return the default entity's flight run (the release node's ball)."""
        return self.sim.run_of(DEFAULT_ENTITY)

    def _on_order(self, msg: String) -> None:
        """
        Fly a valid order and acknowledge it (OK), or refuse it with the reason (ERROR).

        Every order gets exactly one acknowledgement on football/flight/ack, named by the
        order's ``order`` id (else its ``id``): the release node answers its client from it.
        """
        self.tick_gate.wait_clear()
        name = 'unknown'
        try:
            order = FlightOrder.from_json(msg.data)  # one parse; a refusal names the order
            name = order.name
            flight = order.flight(self.integration_step, self._model_override())
        except OrderError as exc:
            name = exc.name
            throttled(
                self.get_logger(), 'error',
                f"refused flight order '{name}': {exc}",
                LOG_THROTTLE_S,
            )
            self._acknowledge(name, 'ERROR', str(exc), {})
            return
        except (ValueError, ArithmeticError, RecursionError) as exc:
            reason = capped(str(exc) or type(exc).__name__)
            throttled(
                self.get_logger(), 'error',
                f"refused flight order '{name}': {reason}",
                LOG_THROTTLE_S,
            )
            self._acknowledge(name, 'ERROR', reason, {})
            return
        except Exception as exc:  # never let one order take the simulator down
            throttled(
                self.get_logger(), 'error',
                f"flight order '{name}': internal error\n{traceback.format_exc()[-4000:]}",
                LOG_THROTTLE_S,
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

    def _start(self, order: FlightOrder, flight: Flight, entity: str = DEFAULT_ENTITY) -> None:
        """Fly ``flight`` as ``entity`` (the default one: the release node's ball) from now on."""
        modes = flight.modes
        v = order.initial.velocity
        who = f"flight '{order.request_id}'" if entity == DEFAULT_ENTITY else f"entity '{entity}'"
        text = (
            f'{who}: {order.ball_name} released at {np.linalg.norm(v):.2f} m/s, '
            f'{math.degrees(modes.flight_path_angle):.1f} deg, {order.initial.spin / RPM:.0f} rpm'
            f' ({"stable" if modes.stable else "gyroscopically UNSTABLE"}, equilibrium sideslip '
            f'{math.degrees(modes.equilibrium_sideslip):.2f} deg)'
        )
        label = order.request_id if entity == DEFAULT_ENTITY else entity
        trail = collections.deque(maxlen=max(self.trail_length, 1))
        run = FlightRun(label, flight, order, trail=trail)
        previous = self.sim.run_of(entity)
        self.sim.throw(entity, run, order)
        self.sim.report('OK' if modes.stable else 'WARN', 'released', text, label)
        if entity != DEFAULT_ENTITY:
            return
        log = self.get_logger()  # each line at most 1 / LOG_THROTTLE_S a second (hammering)
        if previous is not None and previous.flying:
            throttled(
                log, 'info',
                'the flight in the air is replaced by a new release',
                LOG_THROTTLE_S,
            )
        if modes.stable:
            throttled(log, 'info', text, LOG_THROTTLE_S)
        else:
            throttled(log, 'warning', text, LOG_THROTTLE_S)

    def _on_reset(self, _request, response):
        order = self.sim.last_order
        if order is None:
            response.success, response.message = (
                False,
                'no flight to reset: nothing was released yet',
            )
            return response
        try:
            flight = order.flight(self.integration_step, self._model_override())
        except (ValueError, ArithmeticError) as exc:  # e.g. a step too large since a change
            response.success = False
            response.message = f"flight '{order.request_id}' cannot restart: {capped(str(exc))}"
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
        self.sim.set_state(PAUSED if request.data else PLAYING)
        response.success = True
        response.message = 'paused' if request.data else 'running'
        throttled(
            self.get_logger(), 'info',
            f'simulation {response.message}',
            LOG_THROTTLE_S,
        )
        return response

    def _check_rivals(self) -> None:
        """
        Warn when another node publishes our state topics (or /clock, with publish_clock).

        Every publisher but one of our own name counts (two simulators may share a name).
        """
        me = self.get_fully_qualified_name()
        topics = [self.resolve_topic_name(qos.POSE)] + ([qos.CLOCK] if self.publish_clock else [])
        others = set()
        for topic in topics:
            names = [
                _qualified(i.node_namespace, i.node_name)
                for i in self.get_publishers_info_by_topic(topic)
            ]
            if me in names:
                names.remove(me)
            others.update(f'{name} ({topic})' for name in names)
        rivals = tuple(sorted(others))
        before, self._rivals = self._rivals, rivals
        if rivals != before and rivals:
            self.get_logger().warning(
                'another node publishes the same topics, the streams will '
                f'interleave: {", ".join(rivals)}'
            )
        elif rivals != before:
            self.get_logger().info('no other node publishes the state topics any more')

    # --- pacing thread -----------------------------------------------------------------------
    def _pace(self) -> None:
        if self.thread_priority:
            refused = fifo_priority(self.thread_priority)
            if refused:
                self.get_logger().warning(
                    f'thread_priority {self.thread_priority}: SCHED_FIFO refused ({refused}); '
                    'pacing on the normal scheduler (allow it with an rtprio limit, e.g. '
                    '"@realtime - rtprio 99" in /etc/security/limits.conf, or CAP_SYS_NICE)'
                )
            else:
                below = max(1, self.thread_priority - 1)
                refused = fifo_priority(below, self._executor_tid)
                self._scheduling = f'SCHED_FIFO priority {self.thread_priority}' + (
                    f' (executor {below})' if refused is None else
                    f' (executor on the normal scheduler: {refused})')
        self._scheduled.set()
        mono0 = time.monotonic_ns()
        wall0 = time.time_ns()
        next_due = mono0
        next_diag = mono0
        while not self._stop.is_set():
            period_ns = int(round(1e9 / self.publish_rate))
            now = time.monotonic_ns()
            if now < next_due:
                time.sleep(min(next_due - now, 50_000_000) * 1e-9)
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
                self.sim.changed.clear()  # a change from here on wakes a rest below
                while next_due <= now:
                    self._guarded_tick(wall0 + (next_due - mono0), period_ns)
                    next_due += period_ns
                self.tick_gate.announce(next_due, period_ns)
                self.sim.integrate_ahead()  # the next tick's pass, now that this one is out
                events, dropped = self.sim.drain_events()
                if events or dropped:
                    self._log_events(events)
                    self._publish_diagnostics(events, dropped)
                if now >= next_diag:
                    self._publish_diagnostics(None, 0)
                    next_diag = now + int(1e9 / self.diagnostics_rate)
                if not self.publish_clock:
                    next_due = self._rest(next_due, next_diag, period_ns, wall0 - mono0)
            except Exception:
                if not self.context.ok():  # Ctrl-C / SIGTERM shut rclpy down under us: just stop
                    return
                self._log_error_limited(
                    f'pacing error (the pacer continues):\n{traceback.format_exc()}'
                )

    def _rest(self, next_due: int, next_diag: int, period_ns: int, wall_offset: int) -> int:
        """
        Sleep through the ticks that would show nothing; return the next tick's due time.

        While nothing flies and /clock is off, ticks show only resting balls at ``hold_rate``
        (:meth:`.Simulation.quiet_until`): the pacer sleeps (no CPU, no GIL) until one is
        due, /diagnostics is (``next_diag``), or the simulation changes (a service, an order,
        a parameter), and the ticks it slept through move the clock as they would have
        (:meth:`.Simulation.skip`). Times: monotonic ns; ``wall_offset`` wall - monotonic.
        """
        quiet = self.sim.quiet_until(next_due + wall_offset, self.hold_rate)
        wake = next_diag if quiet is None else min(next_diag, quiet - wall_offset)
        if wake - next_due < period_ns:
            return next_due  # something to do at the next tick or the one after
        self.tick_gate.announce(None)  # no tick due: handlers need not give way
        self.sim.changed.wait((wake - time.monotonic_ns()) * 1e-9)
        last = min(time.monotonic_ns(), wake - 1)  # the ticks due before wake, up to now
        passed = (last - next_due) // period_ns + 1
        if passed > 0:
            self.sim.skip(int(passed), period_ns, self.real_time_factor)
            self.stats['ticks'] += int(passed)
            next_due += int(passed) * period_ns
        self.tick_gate.announce(next_due, period_ns)
        return next_due

    def _log_events(self, events) -> None:
        """Log the default ball's landing, guard and data-range events (released: at the order)."""
        log = self.get_logger()
        for level, event, text, _label in events:
            if event == 'released':
                continue
            if level == 'ERROR':
                throttled(log, 'error', text, LOG_THROTTLE_S)
            elif level == 'WARN':
                throttled(log, 'warning', text, LOG_THROTTLE_S)
            else:
                throttled(log, 'info', text, LOG_THROTTLE_S)

    def _guarded_tick(self, wall_stamp_ns: int, period_ns: int) -> None:
        """One tick; an exception ends the flight in the air (ERROR) and pacing goes on."""
        try:
            self._tick(wall_stamp_ns, period_ns)
        except Exception as exc:
            if not self.context.ok():
                raise
            if self._stop.is_set():  # shutting down: the node's handles may be gone already
                return
            text = f'{type(exc).__name__}: {exc}'[:300]
            if self.sim.end_flights(f'internal error while flying ({text})'):
                self.get_logger().error(traceback.format_exc())
            else:
                self._log_error_limited(f'tick failed: {traceback.format_exc()}')

    def _log_error_limited(self, text: str) -> None:
        now = time.monotonic()
        if now - self._last_error_log >= 10.0:
            self._last_error_log = now
            self.get_logger().error(text)

    def _stamp_ns(self, wall_stamp_ns: int, clock_ns: int) -> int:
        """
        Stamp of a tick.

        simulated time (publish_clock), the external /clock (use_sim_time), else the
        wall-clock time the tick was due.
        """
        if self.publish_clock:
            return clock_ns
        if self._use_sim_time:
            return self.get_clock().now().nanoseconds
        return wall_stamp_ns

    def _tick(self, wall_stamp_ns: int, period_ns: int) -> None:
        sim = self.sim
        with sim.lock:
            self.stats['ticks'] += 1
            frame = sim.tick(wall_stamp_ns, period_ns, self.real_time_factor, self.hold_rate)
            stamp = mb.time_msg(self._stamp_ns(wall_stamp_ns, frame.clock_ns))
            if self.publish_clock:
                self._clock_msg.clock = stamp
                self._clock_pub.publish(self._clock_msg)
            if frame.default_t is not None or sim.world.default.run is None:
                self._observation.tick(sim.world.default.run, stamp, frame.default_t)
            if self._rig is not None and frame.default_t is not None:  # camera rig (cameras.py)
                self._rig.tick(sim.world.default.run, stamp, frame.default_t)
            self._publish_frame(frame, stamp, wall_stamp_ns)

    def _publish_frame(self, frame: Frame, stamp, wall_ns: int) -> None:
        """
        Publish a frame (the simulation's lock held).

        The default ball's topics and markers, the spawned balls' pose and odom, one /tf for
        all: each only while somebody subscribes to it (a count: a local rmw query).
        """
        rows = self.sim.world.rows
        if frame.default is not None:
            run = rows[0].run
            self._publish_state(run, frame.default, stamp, frame.default_held)
            if not frame.default_held:
                self._maybe_publish_markers(run, frame.default, stamp, wall_ns,
                                            force=frame.default.landed)
        if frame.shown.size:
            self._publish_entities(frame, rows, stamp)
        ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        if (self._tf_pub is None or not self.publish_tf or not frame.shown.size
                or not self._tf_pub.get_subscription_count()):
            return
        clock, last_ns = self._tf_last
        if clock == self.publish_clock and ns <= last_ns:
            return  # tf2 refuses a repeated or older stamp for a frame
        self._tf_last = (self.publish_clock, ns)
        key = (self.sim.world.rows_version, frame.shown.tobytes(), self.child_frame_id)
        child = self.child_frame_id

        def children() -> list[str]:
            return [child if k == 0 else f'{child}/{rows[k].name}' for k in frame.shown]

        self._tf_pub.publish(self._tf.encode(key, children, self.frame_id, stamp, frame.pose))

    def _publish_entities(self, frame: Frame, rows, stamp) -> None:
        """
        Publish the spawned balls of a frame on football/<name>/pose and .../odom.

        Only topics somebody subscribes to: the subscriber counts (an rmw graph query each) are
        refreshed for at most ``SUBSCRIBER_CHECKS_PER_TICK`` entities a tick, in turn, so a new
        subscriber gets its first message within max_entities / that many ticks; the frame's
        rows of subscribed entities are found with one array lookup.
        """
        self._refresh_subscribers(rows)
        for j in np.flatnonzero(self._wanted[frame.shown]):
            entity = rows[frame.shown[j]]
            pubs = self._entity_pubs.get(entity.name)
            if pubs is None or not entity.spawned:
                continue
            pose_pub, odom_pub, msgs, outs = pubs
            frames = (self.frame_id, f'{self.child_frame_id}/{entity.name}')
            if msgs.frame_ids != frames:
                msgs.frames(*frames)
            pose = frame.pose[j].tolist()
            if outs[1]:
                pose_pub.publish(msgs.pose(stamp, pose[:3], pose[3:]))
            if outs[2]:
                twist = frame.twist[j].tolist()
                odom_pub.publish(msgs.odom(stamp, pose[:3], pose[3:], twist[:3], twist[3:]))

    def _refresh_subscribers(self, rows) -> None:
        """Count the subscribers of a few entities' topics (in turn) and mark the wanted rows."""
        n = len(rows)
        if self._wanted.size < n:
            self._wanted = np.concatenate((self._wanted, np.zeros(n, dtype=bool)))
        if n <= 1:
            return
        for _ in range(min(SUBSCRIBER_CHECKS_PER_TICK, n - 1)):
            self._check_row = self._check_row % (n - 1) + 1  # rows 1..n-1 (0: the default)
            entity = rows[self._check_row]
            pubs = self._entity_pubs.get(entity.name)
            if pubs is None:
                self._wanted[self._check_row] = False
                continue
            outs = pubs[3]
            outs[1] = pubs[0].get_subscription_count() > 0
            outs[2] = pubs[1].get_subscription_count() > 0
            self._wanted[self._check_row] = outs[1] or outs[2]

    # --- simulation_interfaces (simulation_services.py calls these, executor thread) ---------
    def add_entity_publishers(self, entity: Entity) -> None:
        """
        Create a spawned entity's state publishers (its topics counted at once).

        Without QoS-event handlers (:class:`.quiet.QuietNode`): with them, hundreds of entities
        made every service answer take over 100 ms.
        """
        pubs = tuple(
            self.create_publisher(msg_type, qos.entity_topic(entity.name, leaf), qos.STATE)
            for msg_type, leaf in ((PoseStamped, 'pose'), (Odometry, 'odom'))
        )
        msgs = mb.EntityMessages(self.frame_id, f'{self.child_frame_id}/{entity.name}')
        self._entity_pubs[entity.name] = pubs + (msgs, [0, False, False])

    def remove_entity_publishers(self, entities) -> None:
        """Destroy deleted entities' publishers."""
        for entity in entities:
            for pub in self._entity_pubs.pop(entity.name, ())[:2]:
                self.destroy_publisher(pub)

    def stamp_now(self):
        """Return the stamp of a message sent now: simulated clock, /clock or wall clock."""
        return mb.time_msg(self._stamp_ns(time.time_ns(), self.sim.clock_ns))

    def throw_entity(self, name: str, order: FlightOrder, flight: Flight) -> None:
        """Fly ``flight`` as entity ``name`` from now on (the default entity: as a release)."""
        self._start(order, flight, name)

    def reset_world(self, clock: bool, state: bool, spawned: bool) -> None:
        """Reset: the clock to 0, entities back to their spawn poses, spawned ones deleted."""
        self.remove_entity_publishers(self.sim.reset(clock, state, spawned))
        if clock:
            self._tf_last = (None, -1)
        scopes = (('time', clock), ('state', state), ('spawned', spawned))
        throttled(
            self.get_logger(), 'info',
            'reset: ' + ', '.join(k for k, v in scopes if v),
            LOG_THROTTLE_S,
        )

    def set_simulation_state(self, target: int) -> None:
        """Play (1), pause (2) or stop (0: pause and reset everything)."""
        self.remove_entity_publishers(self.sim.set_state(target))
        if target == STOPPED:
            self._tf_last = (None, -1)
        throttled(
            self.get_logger(), 'info',
            f'simulation {STATE_NAMES[target]}',
            LOG_THROTTLE_S,
        )

    def step_world(self, n_steps: int) -> None:
        """
        Lock-step: advance every flight by exactly ``n_steps`` integration steps (paused).

        One compiled pass for every ball; the simulated clock advances by the same and the new
        states are published once, stamped with it (publish_clock), with /clock.
        """
        if n_steps <= 0:
            return
        wall_ns = time.time_ns()
        sim = self.sim
        with sim.lock:
            frame = sim.step_n(n_steps, wall_ns)
            stamp = mb.time_msg(self._stamp_ns(wall_ns, frame.clock_ns))
            if self.publish_clock:
                self._clock_msg.clock = stamp
                self._clock_pub.publish(self._clock_msg)
            self._publish_frame(frame, stamp, wall_ns)

    def _publish_state(self, run: FlightRun, shown: ShownSample, stamp, at_rest: bool) -> None:
        """
        Publish the default ball's state topics (its /tf goes with the frame's).

        Only topics somebody subscribes to, as for a spawned ball (six subscriber counts a
        frame: local rmw queries, no network).
        """
        pubs = self._pubs
        wanted = {topic for topic, pub in pubs.items() if pub.get_subscription_count()}
        if not wanted:
            return
        sample = shown.sample
        msgs = self._state_msgs
        msgs.fill(sample, stamp, self.frame_id, self.child_frame_id, at_rest)
        for topic, msg in ((qos.POSE, msgs.pose), (qos.ODOM, msgs.odom),
                           (qos.SPIN_AXIS, msgs.spin_axis), (qos.AERO_ANGLES, msgs.aero_angles)):
            if topic in wanted:
                pubs[topic].publish(msg)
        linear = msgs.aero_angles_linear.vector
        if math.isfinite(linear.x + linear.y + linear.z):
            if qos.AERO_ANGLES_LINEAR in wanted:
                pubs[qos.AERO_ANGLES_LINEAR].publish(msgs.aero_angles_linear)
        elif not run.linear_diverged:  # the closed form overflowed (an unstable ball, late)
            run.linear_diverged = True
            self.sim.report(
                'WARN',
                'linear_diverged',
                f"flight '{run.label}': the linear prediction overflowed at t = {sample.t:.3f} "
                's; aero_angles_linear is not published for the rest of this flight',
                run.label,
            )
        quasi = msgs.aero_angles_quasi_steady.vector
        if qos.AERO_ANGLES_QUASI_STEADY in wanted and math.isfinite(quasi.x + quasi.y + quasi.z):
            pubs[qos.AERO_ANGLES_QUASI_STEADY].publish(msgs.aero_angles_quasi_steady)

    def _maybe_publish_markers(
        self, run: FlightRun, shown: ShownSample, stamp, wall_ns: int, force: bool
    ) -> None:
        if self.marker_rate <= 0:
            return
        last = run.last_marker_ns
        if not force and last is not None and wall_ns - last < 1e9 / self.marker_rate:
            return
        run.last_marker_ns = wall_ns
        sample = shown.sample
        trail = run.trail
        if trail.maxlen != max(self.trail_length, 1):
            run.trail = trail = collections.deque(trail, maxlen=max(self.trail_length, 1))
        trail.append(mb.point(sample.position))
        run.trail_count += 1
        points = mb.decimated(trail, run.trail_count - len(trail))
        ball = run.flight.ball
        self._markers_pub.publish(
            mb.markers(sample, points, stamp, self.frame_id, ball.length, ball.diameter)
        )

    def _publish_diagnostics(self, events, dropped: int) -> None:
        sim = self.sim
        run = self._run
        stats, rivals = dict(self.stats), self._rivals
        paused = sim.state != PLAYING
        stamp = mb.time_msg(
            sim.clock_ns if self.publish_clock else self.get_clock().now().nanoseconds
        )
        values = {
            'publish_rate': self.publish_rate,
            'real_time_factor': self.real_time_factor,
            'ticks': stats['ticks'],
            'overruns': stats['overruns'],
            'skipped_ticks': stats['skipped'],
            'max_late_ms': round(stats['max_late_ms'], 3),
            'pacing': self._scheduling,
        }
        level, message = 'OK', 'idle: waiting for a release'
        if run is not None:
            flight = run.flight
            values.update(
                {
                    'flight_id': run.label,
                    'ball': run.order.ball_name,
                    'flight_time': run.time,
                    'stable': flight.modes.stable,
                }
            )
            if run.ended is not None:
                level, message = 'ERROR', f"flight '{run.label}' ended: {run.ended}"
            elif run.landing is not None:
                landing = run.landing
                values.update(
                    {
                        'time_of_flight': landing.t,
                        'landing_x': float(landing.position[0]),
                        'landing_y': float(landing.position[1]),
                    }
                )
                message = landed_text(landing.position, landing.t)
            else:
                message = f'flying: t = {run.time:.3f} s'
            if not flight.modes.stable and level == 'OK':
                level, message = 'WARN', message + ' (gyroscopically unstable)'
        if paused:
            message = 'paused; ' + message
        statuses = []
        for ev_level, event, text, label in events or []:
            statuses.append(
                mb.diagnostic_status(
                    self.diagnostic_name + ' event',
                    ev_level,
                    text,
                    dict(values, event=event, **({'flight_id': label} if label else {})),
                    self.hardware_id,
                )
            )
        if dropped:
            statuses.append(
                mb.diagnostic_status(
                    self.diagnostic_name + ' event',
                    'WARN',
                    f'{dropped} older event(s) dropped '
                    f'(at most {MAX_EVENTS} wait for /diagnostics)',
                    dict(values, event='dropped'),
                    self.hardware_id,
                )
            )
        new_overruns = stats['overruns'] - self._overruns_reported
        if events is None:  # periodic status: overruns since the previous one make it WARN
            self._overruns_reported = stats['overruns']
        if new_overruns:
            level = 'WARN' if level == 'OK' else level
            message += f'; {new_overruns} late tick(s) caught up since the last status'
        if rivals:
            level = 'WARN' if level == 'OK' else level
            message += f'; another node publishes the same topics: {", ".join(rivals)}'
            values['other_publishers'] = ', '.join(rivals)
        statuses.append(
            mb.diagnostic_status(self.diagnostic_name, level, message, values, self.hardware_id)
        )
        self._diag_pub.publish(DiagnosticArray(header=mb.header(stamp, ''), status=statuses))

    def close(self) -> None:
        """Stop the pacing and stepping threads (called before the node is destroyed)."""
        self._stop.set()
        self.sim.changed.set()  # out of a rest at once
        self._thread.join(timeout=5.0)
        self.tick_gate.announce(None)  # no handler waits for a tick that will not come
        if self._sim_services is not None:
            self._sim_services.close()


def _qualified(namespace: str, name: str) -> str:
    return f'{namespace.rstrip("/")}/{name}'


def _warm_up() -> None:
    """Load the compiled kernels now, so that the first flight's ticks are not late."""
    from ..physics.precompile import compile_ahead

    compile_ahead()  # every kernel of the nodes and commands (compiled once, then loaded)
    sim = Simulation()
    sim.spawn('warm_up', 'football_ros://american', [0, 0, 0], [0, 0, 0, 1])
    for name in (DEFAULT_ENTITY, 'warm_up'):
        sim.throw(name, FlightRun('warm_up', Flight.from_release(Release())))
    frame = sim.tick(0, 10_000_000, 1.0, 1.0)  # the world's kernel (kernel.advance_many)
    mb.TransformBatch().encode(0, lambda: ['a', 'b'], FIELD_FRAME, mb.time_msg(0), frame.pose)
    sample = Flight.from_release(Release()).sample(10.0)
    mb.StateMessages().fill(sample, mb.time_msg(0), FIELD_FRAME, BODY_FRAME)
    mb.odometry(sample, mb.time_msg(0), FIELD_FRAME, BODY_FRAME)


def main(argv=None) -> int:
    return run_node(SimulatorNode, argv, 'simulator')


if __name__ == '__main__':
    raise SystemExit(main())
