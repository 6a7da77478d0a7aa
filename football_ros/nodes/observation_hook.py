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
The simulator's simulated camera: parameters ``observation_*`` and ``football/observation``.

A thin adapter around :class:`football_ros.estimation.Camera` (the sensor model lives there).
The simulator's pacing thread calls :meth:`ObservationHook.tick` once per tick, before it
samples the flight. Captures are at k / observation_rate of flight time after the release;
each is published observation_latency [s] of flight time later (at the first tick at or after
that), as geometry_msgs/msg/PointStamped in the world frame with header.stamp = the capture
time on the simulator's stamp clock. With ``publish_clock`` false and a real-time factor other
than 1, stamps are wall time and flight seconds are 1 / real_time_factor wall seconds.

Nothing is lost silently: the camera's queue holds rate x latency frames (plus slack), the
fixes still waiting when the ball lands are published at the landing tick (the simulator stops
ticking a landed flight; their stamps are their capture times), and one log line per flight
says how many fixes were published and how many were lost and why (the camera's ``dropout``,
a full queue, a flight replaced in the air). :attr:`ObservationHook.counts` totals them over
the node's life (for /diagnostics).
"""

from __future__ import annotations

import collections

from geometry_msgs.msg import Point, PointStamped

from . import messages as mb
from . import qos
from .params import ParamSpec
from ..estimation.sensor import Camera, CameraSettings, LIMITS

PARAMETERS = tuple(
    ParamSpec(*row, guard='allow_reconfigure')
    for row in (
        (
            'observation_rate',
            0.0,
            'Simulated camera frames per second of flight time [Hz], 0 = off',
            LIMITS['rate'],
        ),
        ('observation_noise', 0.02, 'Camera noise, 1 sigma per axis [m]', LIMITS['noise']),
        ('observation_latency', 0.02, 'Delay from capture to publication [s]', LIMITS['latency']),
        ('observation_dropout', 0.0, 'Probability that a frame is lost', LIMITS['dropout']),
        (
            'observation_outlier_rate',
            0.0,
            'Probability that a frame is an outlier',
            LIMITS['outlier_rate'],
        ),
        (
            'observation_outlier_size',
            2.0,
            'Distance of an outlier from the ball [m]',
            LIMITS['outlier_size'],
        ),
        (
            'observation_seed',
            0,
            "Seed of the camera's noise (each flight restarts it)",
            (0, 2**31 - 1),
        ),
    )
)


class ObservationHook:
    """Owns the camera and the ``football/observation`` publisher of a simulator node."""

    def __init__(self, node) -> None:
        for spec in PARAMETERS:
            setattr(node, spec.name, spec.declare(node))
        self._node = node
        self._pub = node.create_publisher(PointStamped, qos.OBSERVATION, qos.STATE)
        self._camera: Camera | None = None
        self._key: tuple | None = None
        self._run = None
        self._flights = 0
        self._closed = True  # the current camera's flight was summed up in the log
        self.counts: collections.Counter = collections.Counter()
        """Totals over the node's life: 'captured', 'published', 'dropout', 'queue_full',
        'at_landing' (published at the landing tick), 'replaced' (waiting when a new flight
        or new parameters replaced the camera)."""

    def _settings(self) -> CameraSettings:
        n = self._node
        return CameraSettings(
            rate=float(n.observation_rate),
            noise=float(n.observation_noise),
            latency=float(n.observation_latency),
            dropout=float(n.observation_dropout),
            outlier_rate=float(n.observation_outlier_rate),
            outlier_size=float(n.observation_outlier_size),
            seed=int(n.observation_seed) + self._flights,
        )

    def tick(self, run, stamp, now: float) -> None:
        """
        Capture and publish what is due at this tick.

        ``run``: the simulator's flight run, ``stamp``: the tick's builtin_interfaces/Time.
        Call before the tick samples the flight.
        """
        node = self._node
        stamp_ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        if node.observation_rate <= 0.0 or run is None:
            self._close('camera off' if run is not None else 'no flight')
            self._run = None
            return
        flight = run.flight
        new_flight = run is not self._run
        if new_flight:
            self._close('a new flight')
            self._run = run
            self._flights += 1
        key = (
            node.observation_rate,
            node.observation_noise,
            node.observation_latency,
            node.observation_dropout,
            node.observation_outlier_rate,
            node.observation_outlier_size,
            node.observation_seed,
        )
        if new_flight or key != self._key:  # a fresh camera (changed parameters: from now on)
            if not new_flight:
                self._close('new camera parameters')
            self._key = key
            self._camera = Camera(self._settings())
            self._camera.restart(0.0 if new_flight else now)
            self._closed = False
        scale = 1.0 if node.publish_clock else 1.0 / node.real_time_factor
        cam = self._camera
        out = cam.step(now, lambda t: flight.state_at(t)[:3])
        landed = flight.landing_time is not None and now >= flight.landing_time
        if landed and cam.waiting:  # no later tick will come for them: publish them now
            out += cam.flush()
        for obs in out:
            stamp = stamp_ns - int(round((now - obs.stamp) * scale * 1e9))
            x, y, z = (float(v) for v in obs.position)
            msg = PointStamped(
                header=mb.header(mb.time_msg(stamp), node.frame_id), point=Point(x=x, y=y, z=z)
            )
            self._pub.publish(msg)
        if landed:
            self._close('landed')

    def _close(self, why: str) -> None:
        """Sum up the current camera's flight: add its counts, log one line (once)."""
        cam = self._camera
        if cam is None or self._closed:
            return
        self._closed = True
        c = cam.counts
        replaced = cam.waiting
        totals = {
            'captured': c['captured'],
            'published': c['delivered'],
            'dropout': c['dropout'],
            'queue_full': c['queue_full'],
            'at_landing': c['flushed'],
            'replaced': replaced,
        }
        self.counts.update(totals)
        lost = c['queue_full'] + replaced
        text = (
            f"camera, flight {self._flights} ({why}): {c['delivered']} of {c['captured']} "
            f"fixes published ({c['flushed']} at the landing), {c['dropout']} lost to "
            f"observation_dropout, {c['queue_full']} dropped from a full queue, {replaced} "
            'still waiting dropped'
        )
        if lost:
            self._node.get_logger().warning(text)
        else:
            self._node.get_logger().info(text)
