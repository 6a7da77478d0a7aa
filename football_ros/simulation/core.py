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
The whole simulation without ROS: a world of balls, its clock, play / pause / stop and steps.

:class:`Simulation` is what the simulator node serves: every operation (throw, spawn, delete,
place, get states, select, tick, step n, reset by scope, play / pause / stop) takes plain values
and holds the simulation's one lock for as long as it needs it, so that the node's pacing
thread and its services can call it from any thread. Real-time ticks and lock-step go through
the same compiled pass over every ball in the air (:class:`~football_ros.simulation.world.World`);
a tick's next pass can be computed ahead, right after the node has published, so that the next
tick is ready at its deadline. Name filters are compiled (RE2, linear time) before the lock is
taken. Times: the simulated clock in integer nanoseconds; flight times in seconds; ``field``, SI.
"""

from __future__ import annotations

from dataclasses import dataclass
import threading

import numpy as np

from . import names
from .world import DEFAULT_ENTITY, Entity, EntityError, FlightRun, FLYING, ShownSample, World

STOPPED, PLAYING, PAUSED = 0, 1, 2
"""Simulation states (the numbers of simulation_interfaces/SimulationState)."""
STATE_NAMES = ('stopped', 'playing', 'paused')


@dataclass(frozen=True)
class EntityValues:
    """
    One entity's state: pose, twist and acceleration in ``field`` (the twist's frame too).

    position [m], orientation (x, y, z, w; body x = the ball's long axis), velocity [m/s],
    angular_velocity [rad/s], acceleration [m/s^2] (the model's, 0 at rest), condition
    ('at rest', 'flying', 'landed', 'ended'), ball (preset name).
    """

    name: str
    ball: str
    condition: str
    position: np.ndarray
    orientation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    acceleration: np.ndarray


@dataclass
class Frame:
    """
    What one tick or step shows: rows ``shown`` of the world and their values then.

    ``pose`` (N, 7: x, y, z [m], qx, qy, qz, qw), ``twist`` (N, 6: v [m/s], w [rad/s]; zero
    for a ball at rest or landed and held), ``held`` (N,) True for a resting state shown again,
    ``clock_ns`` the simulated clock, ``default`` the default ball's
    :class:`~football_ros.simulation.world.ShownSample` when it is shown (its sample built if
    read) and ``default_held``; ``default_t`` the flight time [s] the tick asked of the
    default ball while it flew (its landing may come before).
    """

    shown: np.ndarray
    pose: np.ndarray
    twist: np.ndarray
    held: np.ndarray
    clock_ns: int
    default: ShownSample | None = None
    default_held: bool = False
    default_t: float | None = None


def _values(entity: Entity) -> EntityValues:
    position, orientation, velocity, omega = entity.state()
    return EntityValues(entity.name, entity.ball_name, entity.condition, position, orientation,
                        velocity, omega, entity.acceleration())


class Simulation:
    """
    The simulation: a :class:`World`, the simulated clock and the play state, behind one lock.

    ``step``: the integration step [s] of new flights and of lock-step; ``max_entities``: the
    world's limit. Attributes ``world`` and ``lock`` are for a caller that publishes a frame
    (it holds ``lock`` while it reads the frame's entities); every change goes through a method.
    ``changed`` (a threading.Event) is set by every change a tick may have to show or report
    (spawn, delete, place, throw, play state, reset, a queued event), so that a pacer resting
    while nothing flies (:meth:`quiet_until`) wakes for it; the pacer clears it.
    """

    def __init__(self, max_entities: int = 100, step: float = 0.001) -> None:
        self.lock = threading.RLock()
        self.world = World(max_entities)
        self.step = float(step)
        self.clock_ns = 0
        self.state = PLAYING
        self.last_order = None  # the default ball's last order (opaque: the node's)
        self._ahead = None
        self.changed = threading.Event()

    # --- the world's entities ---------------------------------------------------------------
    @property
    def max_entities(self) -> int:
        return self.world.max_entities

    @max_entities.setter
    def max_entities(self, value: int) -> None:
        with self.lock:
            self.world.max_entities = max(1, int(value))

    def spawn(self, name: str, uri: str, position, orientation,
              allow_renaming: bool = False) -> Entity:
        """Add a ball at rest (see :meth:`World.spawn`; EntityError names what is wrong)."""
        with self.lock:
            entity = self.world.spawn(name, uri, position, orientation, allow_renaming)
            self.changed.set()
            return entity

    def delete(self, name: str) -> Entity:
        """Remove a spawned ball (EntityError 'not_found' or 'default')."""
        with self.lock:
            entity = self.world.delete(name)
            self.changed.set()
            return entity

    def place(self, name: str, position, orientation) -> None:
        """Put a ball at rest at a pose (its flight dropped; EntityError 'not_found', 'pose')."""
        with self.lock:
            self.world.place(self.world.get(name), position, orientation)
            self.changed.set()

    def throw(self, name: str, run: FlightRun, order=None) -> FlightRun:
        """
        Fly ``run`` as entity ``name`` from its release on (EntityError 'not_found').

        For the default entity ``order`` is kept as the last order (what a restart flies).
        """
        with self.lock:
            entity = self.world.get(name)
            self.world.throw(entity, run)
            if name == DEFAULT_ENTITY and order is not None:
                self.last_order = order
            self.changed.set()
            return run

    def run_of(self, name: str) -> FlightRun | None:
        """Return the flight run entity ``name`` flies (None at rest; EntityError)."""
        with self.lock:
            return self.world.get(name).run

    def ball_of(self, name: str) -> str:
        """Return the ball preset of entity ``name`` (EntityError 'not_found')."""
        with self.lock:
            return self.world.get(name).ball_name

    def entity_state(self, name: str) -> EntityValues:
        """Entity ``name``'s state now (EntityError 'not_found')."""
        with self.lock:
            return _values(self.world.get(name))

    def describe(self, name: str) -> tuple[str, str, list[str]]:
        """(uri, condition, tags) of entity ``name`` (EntityError 'not_found')."""
        with self.lock:
            entity = self.world.get(name)
            return entity.uri, entity.condition, self.world.tags(entity)

    def select(self, pattern: str = '', tags: tuple[str, ...] = (), all_tags: bool = False,
               sphere=None, box=None, states: bool = False) -> list:
        """
        Names of the entities passing the filters (:meth:`World.select`), or their states.

        The name filter is compiled before the lock is taken (RE2: linear in the name, whatever
        the pattern); EntityError('filter') for a bad one. ``states``: EntityValues instead.
        """
        try:
            matcher = names.compile_filter(pattern)
        except names.FilterError as exc:
            raise EntityError('filter', str(exc)) from None
        with self.lock:
            entities = self.world.select(matcher, tags, all_tags, sphere, box)
            return [_values(e) for e in entities] if states else [e.name for e in entities]

    def report(self, level: str, event: str, text: str, label: str = '') -> None:
        """Queue an event (level 'OK', 'WARN' or 'ERROR'; ``label``: its flight's) to drain."""
        with self.lock:
            self.world.events.append((level, event, text, label))
            self.changed.set()

    def end_flights(self, reason: str) -> int:
        """End every flight in the air (ERROR events, e.g. after an internal error); count."""
        with self.lock:
            self.changed.set()
            return self.world.end_all(reason)

    def flying_count(self) -> int:
        """How many balls are in the air."""
        with self.lock:
            return int(self.world.flying().size)

    def drain_events(self) -> tuple[list, int]:
        """Events (level, event, text, label) queued since the last call, and how many dropped."""
        with self.lock:
            events = self.world.events
            out, dropped = list(events), events.dropped
            events.clear()
            events.dropped = 0
            return out, dropped

    # --- time -------------------------------------------------------------------------------
    def set_state(self, target: int) -> list[Entity]:
        """
        Play, pause or stop (STOPPED: paused, clock 0, spawned balls deleted, every ball reset).

        Returns the entities deleted.
        """
        with self.lock:
            doomed = self.reset(True, True, True) if target == STOPPED else []
            self.state = target
            self.changed.set()
            return doomed

    def reset(self, time: bool, state: bool, spawned: bool) -> list[Entity]:
        """Reset by scope: the clock to 0, balls to their spawn poses, spawned ones deleted."""
        with self.lock:
            doomed = self.world.reset(state=state, spawned=spawned)
            if time:
                self.clock_ns = 0
            self._ahead = None
            self.changed.set()
            return doomed

    def tick(self, wall_ns: int, period_ns: int, real_time_factor: float,
             hold_rate: float) -> Frame:
        """
        One real-time tick of ``period_ns`` wall nanoseconds; return what it shows.

        Playing: the clock moves on by period x real_time_factor and every ball in the air is
        shown at its next flight time (each tick real_time_factor x period of flight later).
        Resting balls are shown at once after a change, then at ``hold_rate`` [Hz] of wall time
        ``wall_ns`` (paused: only balls at rest, no landed ones).
        """
        with self.lock:
            playing = self.state == PLAYING
            world = self.world
            asked = None
            if playing and world.status[0] == FLYING:
                asked = float(world.next_t[0])
            if playing:
                self.clock_ns += int(period_ns * real_time_factor)
                moved = world.fly(real_time_factor * period_ns * 1e-9, wall_ns, self._ahead)
            else:
                moved = np.empty(0, dtype=np.int64)
            self._ahead = None
            frame = self._frame(moved, world.due(wall_ns, hold_rate, landed=playing))
            frame.default_t = asked
            return frame

    def quiet_until(self, wall_ns: int, hold_rate: float) -> int | None:
        """
        Wall time [ns] before which no tick would show, move or report anything.

        ``wall_ns`` while a ball flies (playing) or an event waits: every tick has work; else
        when the next resting ball is due (:meth:`World.next_due_ns`, the rules of
        :meth:`tick`), None if none is until a change. Meanwhile a playing tick only moves the
        clock (:meth:`skip`); a paused one does nothing.
        """
        with self.lock:
            world, playing = self.world, self.state == PLAYING
            if world.events or world.events.dropped or (playing and world.flying().size):
                return wall_ns
            due = world.next_due_ns(hold_rate, landed=playing)
            return None if due is None else max(due, wall_ns)

    def skip(self, ticks: int, period_ns: int, real_time_factor: float) -> None:
        """
        Let ``ticks`` ticks with nothing to show pass (:meth:`quiet_until`).

        Playing, the clock moves on as they would have moved it; paused, nothing changes.
        """
        with self.lock:
            if self.state == PLAYING:
                self.clock_ns += ticks * int(period_ns * real_time_factor)

    def integrate_ahead(self) -> None:
        """Compute the next tick's pass now (after publishing); a change meanwhile voids it."""
        with self.lock:
            self._ahead = self.world.ahead() if self.state == PLAYING else None

    def step_n(self, n_steps: int, wall_ns: int) -> Frame:
        """
        Lock-step: every ball in the air exactly ``n_steps`` integration steps on.

        The clock moves on by the same; the simulation is left paused (a STOPPED one too).
        """
        with self.lock:
            self._ahead = None
            if self.state != PLAYING:
                self.state = PAUSED
            self.clock_ns += int(round(n_steps * self.step * 1e9))
            moved = self.world.advance(n_steps, self.step, wall_ns)
            if self.world.events:  # a landing or an ended flight: the pacer reports it
                self.changed.set()
            return self._frame(moved, np.empty(0, dtype=np.int64))

    def _frame(self, moved: np.ndarray, held: np.ndarray) -> Frame:
        world = self.world
        twist = world.twist[moved]
        if held.size:
            shown = np.union1d(moved, held)
            is_held = np.isin(shown, held)
            twist = world.twist[shown]
            twist[is_held] = 0.0
        else:
            shown, is_held = moved, np.zeros(moved.size, dtype=bool)
        frame = Frame(shown, world.pose[shown], twist, is_held, self.clock_ns)
        if shown.size and shown[0] == 0 and world.default.run is not None:
            frame.default = ShownSample(world, world.default)
            frame.default_held = bool(is_held[0])
        return frame
