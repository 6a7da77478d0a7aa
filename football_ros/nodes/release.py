"""Release node: release conditions in, one accept/reject answer out, flight order to the simulator.

Requests: ``football/release/request`` (std_msgs/String, YAML or JSON mapping) or
``football/release/state`` (nav_msgs/Odometry, the full rigid-body release state). Every
request gets exactly one ``football/release/response`` (diagnostic_msgs/DiagnosticStatus) with
name = the request id. An accepted release is sent to the simulator on ``football/flight/order``
and replaces any flight in the air. Contract and ranges: msg_docs/release.md.
"""

from __future__ import annotations

import math
import traceback

import numpy as np

from diagnostic_msgs.msg import DiagnosticStatus
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from std_msgs.msg import String

from ..physics import Flight, InitialState, ReleaseError, get_preset
from ..physics.frames import FIELD_FRAME
from ..requests import (MAX_REQUEST_BYTES, FlightOrder, RequestError, flight_summary,
                        parse_release_request)
from . import messages as mb
from . import qos
from .params import declare
from .runner import run_node

NODE_NAME = "football_release"
PREDICTION_HORIZON_S = 60.0


def prediction(flight: Flight) -> dict[str, object]:
    """Linear-theory numbers and the headless flight's landing, as response values."""
    m = flight.modes
    trajectory = flight.simulate(rate=100.0, duration=PREDICTION_HORIZON_S)
    values: dict[str, object] = {
        "omega_fast": m.omega_fast, "omega_slow": m.omega_slow, "critical_spin_rpm": m.critical_spin_rpm,
        "equilibrium_sideslip": m.equilibrium_sideslip, "stable": m.stable, "m_alpha": m.m_alpha,
        "h1": m.h1, "gyroscopic_stability_factor": m.gyroscopic_stability_factor,
    }
    values.update(flight_summary(trajectory.times, trajectory.positions, trajectory.landed))
    if trajectory.landed:
        values.update({"landing_x": float(trajectory.positions[-1, 0]),
                       "landing_y": float(trajectory.positions[-1, 1])})
    return values


class ReleaseNode(Node):
    """Validates release requests, answers each one, and orders accepted flights."""

    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        self.max_request_bytes = declare(self, "max_request_bytes", MAX_REQUEST_BYTES,
                                         "Largest accepted request text [bytes]", (64, 1 << 20))
        self.integration_step = declare(self, "integration_step", 0.001,
                                        "Integration step of the landing prediction [s]", (1e-5, 0.01))
        self.add_on_set_parameters_callback(self._on_parameters)  # ranges: enforced by descriptors
        self._responses = self.create_publisher(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
        self._orders = self.create_publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
        self.create_subscription(String, qos.RELEASE_REQUEST, self._on_request, qos.REQUEST)
        self.create_subscription(Odometry, qos.RELEASE_STATE, self._on_state, qos.REQUEST)
        self.counts = {"accepted": 0, "rejected": 0}
        self.get_logger().info(
            f"ready: requests on '{self.resolve_topic_name(qos.RELEASE_REQUEST)}' and "
            f"'{self.resolve_topic_name(qos.RELEASE_STATE)}', answers on "
            f"'{self.resolve_topic_name(qos.RELEASE_RESPONSE)}'")

    def _on_parameters(self, params) -> SetParametersResult:
        for p in params:
            if p.name != "use_sim_time":
                setattr(self, p.name, p.value)
        return SetParametersResult(successful=True)

    def _on_request(self, msg: String) -> None:
        request_id = "unknown"
        try:
            request_id, release = parse_release_request(msg.data, self.max_request_bytes)
            answer = self._decide(FlightOrder.from_release(request_id, release))
        except RequestError as exc:
            answer = self._rejection(exc.request_id, str(exc))
        except Exception as exc:  # never let one request take the node down
            answer = self._internal_error(request_id, exc)
        self._respond(*answer)

    def _on_state(self, msg: Odometry) -> None:
        stamp = msg.header.stamp
        request_id = f"state:{stamp.sec}.{stamp.nanosec:09d}"
        try:
            if msg.header.frame_id not in ("", FIELD_FRAME):
                raise ReleaseError(f"header.frame_id must be '{FIELD_FRAME}' (or empty), "
                                   f"got '{msg.header.frame_id[:40]}'")
            ball = msg.child_frame_id or "american"
            get_preset(ball)
            pose, twist = msg.pose.pose, msg.twist.twist
            initial = InitialState.from_rigid_body(
                mb.vector_of(pose.position), mb.vector_of(twist.linear),
                [pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w],
                mb.vector_of(twist.angular))
            answer = self._decide(FlightOrder(request_id, ball, {}, "paper", "linear", initial))
        except (ReleaseError, ValueError) as exc:
            answer = self._rejection(request_id, str(exc))
        except Exception as exc:
            answer = self._internal_error(request_id, exc)
        self._respond(*answer)

    def _decide(self, order: FlightOrder) -> tuple[str, str, str, dict]:
        """Accept (and order the flight) or reject; returns the answer to publish."""
        try:
            flight = order.flight(self.integration_step)
        except ValueError as exc:
            return self._rejection(order.request_id, str(exc))
        values = prediction(flight)
        if self._orders.get_subscription_count() == 0:
            return self._rejection(order.request_id, "valid release, but no simulator is listening on "
                                   f"'{self.resolve_topic_name(qos.FLIGHT_ORDER)}' (start: ros2 run "
                                   "football_ros simulator)", values)
        self._orders.publish(String(data=order.to_json()))
        stable = flight.modes.stable
        tof = values["time_of_flight"]
        text = (f"accepted: {order.ball_name} at {np.linalg.norm(order.initial.velocity):.2f} m/s; "
                + (f"lands at {values['range']:.2f} m after {tof:.3f} s" if not math.isnan(tof)
                   else f"still flying after {PREDICTION_HORIZON_S:g} s")
                + ("" if stable else "; WARNING: gyroscopically unstable "
                   f"(spin below {values['critical_spin_rpm']:.0f} rpm), the ball will tumble"))
        self.counts["accepted"] += 1
        if stable:
            self.get_logger().info(f"request '{order.request_id}' {text}")
        else:
            self.get_logger().warning(f"request '{order.request_id}' {text}")
        return order.request_id, "OK" if stable else "WARN", text, values

    def _rejection(self, request_id: str, reason: str, values: dict | None = None):
        self.counts["rejected"] += 1
        self.get_logger().warning(f"request '{request_id}' rejected: {reason}")
        return request_id, "ERROR", f"rejected: {reason}", values or {}

    def _internal_error(self, request_id: str, exc: Exception):
        self.get_logger().error(f"request '{request_id}': internal error\n{traceback.format_exc()}")
        return self._rejection(request_id, f"internal error ({type(exc).__name__}: {exc})")

    def _respond(self, request_id: str, level: str, message: str, values: dict) -> None:
        self._responses.publish(mb.diagnostic_status(request_id, level, message, values,
                                                     hardware_id="football_ros/release"))


def main(argv=None) -> int:
    return run_node(ReleaseNode, argv, "release")


if __name__ == "__main__":
    raise SystemExit(main())
