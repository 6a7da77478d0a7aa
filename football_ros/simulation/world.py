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
A world of named balls, each an entity that may carry a flight run (no ROS).

:class:`World` holds the entities by name (the default entity ``football`` always exists; the
others are spawned, up to a limit), validates names and poses, filters entities, and keeps
every ball's numbers in arrays (one row an entity) that one compiled call advances for all
balls in the air: real-time ticks (:meth:`World.fly`) and lock-step (:meth:`World.advance`)
take the same path, the default ball's included. :class:`FlightRun` is a flight's
bookkeeping (its Flight, label, trail, the guard's verdict). What happens is queued as events
(level, event, text) for /diagnostics, at most ``MAX_EVENTS`` of them.

Not thread-safe: :class:`football_ros.simulation.core.Simulation` holds one lock around it.
Everything is in ``field`` and SI.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass, field
import math
import re

import numpy as np

from . import kernel, names
from ..physics import dynamics as dyn, step_stability
from ..physics.aero import max_valid_delta, out_of_validity
from ..physics.flight import BallSample, Flight
from ..physics.presets import PRESETS

DEFAULT_ENTITY = 'football'
"""Name of the entity the release node's orders fly (today's single-ball topics)."""
MAX_EVENTS = 32
"""Events (released, landed, ERROR, ...) waiting for /diagnostics; older ones are dropped."""
MAX_FLIGHT_S = 600.0
"""A flight still in the air after this many simulated seconds is ended (ERROR)."""
MAX_DISTANCE_M = 1.0e5
"""A ball farther than this from its release point [m] is a runaway (ERROR)."""
RUNAWAY_FACTOR = 10.0
"""A speed or angular rate this many times the bound the release allows is a runaway."""
NAME_PATTERN = re.compile(r'[A-Za-z][A-Za-z0-9_]{0,62}')
"""An entity name: a letter, then up to 62 letters, digits or underscores (a topic token)."""
URI_SCHEME = 'football_ros://'
"""Spawnable URIs: this scheme and a ball preset (``football_ros://american``)."""
MAX_POSITION_M = 1.0e4
"""Largest coordinate of a spawn or entity pose [m]."""


class EntityError(ValueError):
    """A refused world operation; ``reason`` names the kind (the node maps it to a code)."""

    def __init__(self, reason: str, text: str) -> None:
        super().__init__(text)
        self.reason = reason


class Events(collections.deque):
    """Bounded event queue (level, event, message, flight label); counts what it dropped."""

    def __init__(self) -> None:
        super().__init__(maxlen=MAX_EVENTS)
        self.dropped = 0

    def append(self, item) -> None:
        if len(self) == self.maxlen:
            self.dropped += 1
        super().append(item)


AT_REST, FLYING, LANDED, ENDED = 0, 1, 2, 3
"""An entity's condition (:attr:`World.status`): at rest, flying, landed, or ended by the guard."""
CONDITIONS = ('at rest', 'flying', 'landed', 'ended')
POSE_WIDTH = 7
"""A row of :attr:`World.pose`: position x, y, z [m], orientation x, y, z, w."""


@dataclass(eq=False)
class FlightRun:
    """
    One flight's bookkeeping: its label (the release's id), the Flight and the order it came from.

    The flight's numbers (state, time flown, condition) live in the world's arrays, in the row
    of the entity that flies it; ``time`` and ``ended`` read them there.
    """

    label: str
    flight: Flight
    order: object = None
    last_hold_ns: int = 0
    last_marker_ns: int | None = None
    trail: collections.deque = field(default_factory=lambda: collections.deque(maxlen=500))
    trail_count: int = 0  # positions ever appended to the trail
    ended: str | None = None  # why the guard ended the flight (ERROR), None while fine
    linear_diverged: bool = False  # the linear prediction overflowed (unstable ball)
    bounds: tuple[float, float] | None = None  # runaway speed [m/s] and rate [rad/s]
    landing: BallSample | None = None  # the landing sample, once landed
    entity: 'Entity | None' = field(default=None, repr=False)  # who flies it (World.throw)

    @property
    def time(self) -> float:
        """Return the simulated seconds flown since the release (the latest state's)."""
        entity = self.entity
        if entity is None or entity.run is not self:
            return self.landing.t if self.landing is not None else 0.0
        return float(entity.world.flown[entity.slot])

    @property
    def landed_reported(self) -> bool:
        return self.landing is not None

    @property
    def flying(self) -> bool:
        """In the air: neither landed nor ended by the guard."""
        return self.ended is None and self.landing is None

    def runaway(self, sample: BallSample) -> str | None:
        """Why ``sample`` must not be published (the flight then ends), or None."""
        values = np.concatenate(
            (
                sample.position,
                sample.velocity,
                sample.orientation,
                sample.axis,
                sample.angular_velocity,
                sample.aero_angles,
            )
        )
        if not np.isfinite(values).all():
            return f'the state became non-finite at t = {sample.t:.4f} s'
        if self.bounds is None:
            self.bounds = runaway_bounds(self.flight)
        bounds = self.bounds
        speed = float(np.linalg.norm(sample.velocity))
        if speed > bounds[0]:
            return (
                f'runaway: speed {speed:.4g} m/s at t = {sample.t:.4f} s, far past the '
                f'{bounds[0] / RUNAWAY_FACTOR:.4g} m/s the release allows'
            )
        rate = float(np.linalg.norm(sample.angular_velocity))
        if rate > bounds[1]:
            return (
                f'runaway: angular rate {rate:.4g} rad/s at t = {sample.t:.4f} s, far past '
                f'the {bounds[1] / RUNAWAY_FACTOR:.4g} rad/s the release allows'
            )
        distance = float(np.linalg.norm(sample.position - self.flight.initial.position))
        if distance > MAX_DISTANCE_M:
            return f'runaway: {distance:.4g} m from the release point at t = {sample.t:.4f} s'
        if not sample.landed and sample.t > MAX_FLIGHT_S:
            return f'no landing within {MAX_FLIGHT_S:g} s of simulated flight'
        return None

    def validity_text(self, sample: BallSample) -> str:
        """Return the warning for a total angle past a data range (lists which)."""
        flight = self.flight
        return (
            f"flight '{self.label}' left the data range at t = {sample.t:.3f} s: "
            + '; '.join(
                out_of_validity(
                    float(sample.aero_angles[2]), flight.model, flight.moment, flight.aero,
                    flight.ball,
                )
            )
        )

    def end(self, reason: str) -> str | None:
        """End the flight (the guard); return the ERROR event's text, None if already ended."""
        if self.ended is not None:
            return None
        self.ended = reason
        return f"flight '{self.label}' ended: {reason}"


def runaway_bounds(flight: Flight) -> tuple[float, float]:
    """
    Speed [m/s] and angular rate [rad/s] past which a flight is a runaway.

    RUNAWAY_FACTOR times the bounds of :mod:`football_ros.physics.step_stability` (ground
    speed <= air speed + wind; |w| <= transverse bound + |p|).
    """
    wind = flight.params[step_stability.dyn.P_WIND:step_stability.dyn.P_WIND + 3]
    speed = step_stability.max_air_speed(flight.initial, wind) + float(np.linalg.norm(wind))
    rate = step_stability.fastest_rates(flight.params, flight.initial)['angular rate'] + abs(
        flight.initial.spin
    )
    return RUNAWAY_FACTOR * speed, RUNAWAY_FACTOR * rate


def landed_text(position, time_of_flight: float) -> str:
    return (
        f'landed at x = {position[0]:.3f} m, y = {position[1]:.3f} m after {time_of_flight:.4f} s'
    )


@dataclass(eq=False)
class Entity:
    """
    A ball in the world: at rest at ``rest_pose`` or flying ``run``; its numbers are the world's.

    ``rest_pose``: (position [m], orientation x, y, z, w) in ``field``, the spawn pose (or
    where SetEntityState put it at rest). ``slot``: its row in the world's arrays.
    """

    name: str
    ball_name: str
    rest_pose: tuple[np.ndarray, np.ndarray]
    world: 'World' = field(repr=False)
    slot: int = 0
    spawned: bool = True
    run: FlightRun | None = None
    spawn_pose: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def uri(self) -> str:
        return URI_SCHEME + self.ball_name

    @property
    def status(self) -> int:
        """AT_REST, FLYING, LANDED or ENDED."""
        return int(self.world.status[self.slot])

    @property
    def condition(self) -> str:
        """'at rest', 'flying', 'landed' or 'ended' (the guard ended its flight)."""
        return CONDITIONS[self.status]

    @property
    def last(self) -> BallSample | None:
        """Return the latest state of its flight as a sample (None at rest)."""
        return None if self.run is None else self.world.sample_of(self)

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position [m], orientation (x, y, z, w), velocity [m/s], angular velocity [rad/s]."""
        world, k = self.world, self.slot
        status = world.status[k]
        if status == AT_REST:
            position, orientation = self.rest_pose
            return position.copy(), orientation.copy(), np.zeros(3), np.zeros(3)
        pose = world.pose[k]
        if status == LANDED:  # at rest on the ground
            return pose[:3].copy(), pose[3:].copy(), np.zeros(3), np.zeros(3)
        twist = world.twist[k]
        return pose[:3].copy(), pose[3:].copy(), twist[:3].copy(), twist[3:].copy()

    def acceleration(self) -> np.ndarray:
        """Return the model's linear acceleration [m/s^2] in ``field`` now (0 at rest)."""
        world, k = self.world, self.slot
        if world.status[k] != FLYING or self.run is None:
            return np.zeros(3)
        rate = np.empty(dyn.N_STATE)
        dyn.derivative(world.full[k], world.params[k], rate)
        return rate[dyn.V:dyn.V + 3].copy()


def check_pose(position, orientation) -> tuple[np.ndarray, np.ndarray]:
    """
    Validate a pose in ``field`` and return it (the quaternion normalised).

    Finite, |coordinates| <= MAX_POSITION_M, z >= 0, a unit quaternion (x, y, z, w) within
    1e-3. Raises EntityError('pose').
    """
    p = np.asarray(position, dtype=float).reshape(-1)
    q = np.asarray(orientation, dtype=float).reshape(-1)
    if p.size != 3 or not np.isfinite(p).all():
        raise EntityError('pose', f'position must be 3 finite numbers, got {p.tolist()}')
    if np.abs(p).max() > MAX_POSITION_M or p[2] < 0.0:
        raise EntityError(
            'pose',
            f'position {p.tolist()} is outside the field (|x|, |y|, z <= {MAX_POSITION_M:g} m, '
            'z >= 0)',
        )
    if q.size != 4 or not np.isfinite(q).all():
        raise EntityError('pose', f'orientation must be 4 finite numbers, got {q.tolist()}')
    norm = math.hypot(*(float(v) for v in q))
    if abs(norm - 1.0) > 1e-3:
        raise EntityError('pose', f'orientation must be a unit quaternion, |q| = {norm:.6g}')
    return p, q / norm


@dataclass
class Computed:
    """A kernel pass over rows ``slots`` at flight times ``times`` [s], not yet committed."""

    version: int
    slots: np.ndarray
    times: np.ndarray
    out: np.ndarray
    described: np.ndarray
    landing: np.ndarray
    fine: np.ndarray


class World:
    """
    Named entities (balls), the default one included, at most ``max_entities`` of them.

    Every entity owns one row of the world's arrays (structure of arrays, in ``field``, SI):
    ``pose`` (N, 7) and ``twist`` (N, 6) of its latest state, ``status``, ``flown`` (flight
    time of that state [s]) and ``next_t`` (the flight time the next real-time tick shows);
    flights also ``y`` (the committed state after ``done`` whole steps of ``steps``),
    ``params``, ``full`` (the latest state vector) and ``described``. All flying balls advance
    in one :func:`kernel.advance_many` call; only balls with an event (landed, ended, left a data
    range) cost Python work. Names follow :data:`NAME_PATTERN`; the default entity (row 0) cannot
    be deleted. Not thread-safe: :class:`football_ros.simulation.core.Simulation` holds its lock.
    """

    def __init__(self, max_entities: int = 100, default_ball: str = 'american') -> None:
        self.max_entities = max(1, int(max_entities))
        self.events = Events()
        self.entities: dict[str, Entity] = {}
        self.rows: list[Entity] = []  # row -> entity
        self._tick_dt = 0.0  # flight seconds per real-time tick, as last flown
        self.version = 0  # changes with every change that a computed pass must not outlive
        self.rows_version = 0  # changes when an entity is added or removed (rows renumbered)
        self._capacity = 0
        self._grow(16)
        self._default_ball = default_ball
        self._add(DEFAULT_ENTITY, default_ball, (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])),
                  spawned=False)
        self._counter = 0

    @property
    def size(self) -> int:
        return len(self.rows)

    def _grow(self, capacity: int) -> None:
        n = self._capacity
        arrays = {
            'pose': (POSE_WIDTH,), 'twist': (6,), 'status': (), 'flown': (), 'next_t': (),
            'tick_base': (), 'ticks': (),
            'shown_ns': (), 'y': (dyn.N_STATE,), 'full': (dyn.N_STATE,), 'done': (),
            'steps': (), 'params': (dyn.N_PARAM,), 'bounds': (2,), 'origins': (3,),
            'valid_delta': (), 'warned': (), 'described': (dyn.N_DESCRIBE,),
        }
        dtypes = {'status': np.int8, 'shown_ns': np.int64, 'done': np.int64, 'warned': bool,
                  'ticks': np.int64}
        for name, shape in arrays.items():
            new = np.zeros((capacity, *shape), dtype=dtypes.get(name, float))
            if n:
                new[:n] = getattr(self, name)[:n]
            setattr(self, name, new)
        self.steps[n:] = 1.0
        self._capacity = capacity

    def _add(self, name: str, ball: str, pose, spawned: bool) -> Entity:
        if self.size == self._capacity:
            self._grow(2 * self._capacity)
        entity = Entity(name, ball, pose, self, self.size, spawned=spawned, spawn_pose=pose)
        self.rows.append(entity)
        self.entities[name] = entity
        self.rows_version += 1
        self._rest(entity, pose)
        return entity

    def _rest(self, entity: Entity, pose) -> None:
        """Put ``entity`` at rest at ``pose`` (its flight dropped), due to be shown at once."""
        k = entity.slot
        entity.rest_pose, entity.run = pose, None
        self.status[k], self.shown_ns[k] = AT_REST, -1
        self.pose[k, :3], self.pose[k, 3:] = pose
        self.twist[k] = 0.0
        self.version += 1

    @property
    def default(self) -> Entity:
        return self.rows[0]

    def get(self, name: str) -> Entity:
        """Return the entity called ``name``; EntityError('not_found') otherwise."""
        entity = self.entities.get(name) if isinstance(name, str) else None
        if entity is None:
            raise EntityError('not_found', f"no entity named '{_brief(name)}'")
        return entity

    def spawn(
        self,
        name: str,
        uri: str,
        position,
        orientation,
        allow_renaming: bool = False,
    ) -> Entity:
        """
        Add a ball at rest at the pose; return it (its name may be generated when renaming).

        Raises EntityError: 'name_invalid', 'name_not_unique', 'no_resource',
        'unsupported_format', 'not_found' (an unknown preset), 'pose' or 'limit'.
        """
        if not uri:
            raise EntityError('no_resource', 'uri is empty (spawnables: GetSpawnables)')
        if not uri.startswith(URI_SCHEME):
            raise EntityError(
                'unsupported_format',
                f"uri '{_brief(uri)}' is not a {URI_SCHEME}<ball> URI "
                f"(known: {', '.join(URI_SCHEME + b for b in PRESETS)})",
            )
        ball = uri[len(URI_SCHEME):]
        if ball not in PRESETS:
            raise EntityError(
                'not_found',
                f"no spawnable '{_brief(uri)}' (known: "
                f"{', '.join(URI_SCHEME + b for b in PRESETS)})",
            )
        pose = check_pose(position, orientation)
        if len(self.entities) >= self.max_entities:
            raise EntityError(
                'limit',
                f'the world holds its limit of {self.max_entities} entities (parameter '
                'max_entities); delete one first',
            )
        if not name:
            if not allow_renaming:
                raise EntityError('name_invalid', 'name is empty and allow_renaming is false')
            name = self._fresh('ball')
        elif not NAME_PATTERN.fullmatch(name):
            raise EntityError(
                'name_invalid',
                f"name '{_brief(name)}' is invalid: a letter, then up to 62 letters, digits or "
                'underscores',
            )
        elif name in self.entities:
            if not allow_renaming:
                raise EntityError('name_not_unique', f"an entity named '{name}' exists")
            name = self._fresh(name[:50])
        return self._add(name, ball, pose, spawned=True)

    def _fresh(self, stem: str) -> str:
        while True:
            self._counter += 1
            name = f'{stem}_{self._counter}'
            if name not in self.entities:
                return name

    def delete(self, name: str) -> Entity:
        """Remove a spawned entity; EntityError('not_found' or 'default') otherwise."""
        entity = self.get(name)
        if not entity.spawned:
            raise EntityError(
                'default',
                f"the default entity '{name}' cannot be deleted (ResetSimulation clears it)",
            )
        self._remove(entity)
        return entity

    def _remove(self, entity: Entity) -> None:
        """Drop ``entity``: the last row moves into its row."""
        k, last = entity.slot, self.size - 1
        if k != last:
            moved = self.rows[last]
            for name in ('pose', 'twist', 'status', 'flown', 'next_t', 'tick_base', 'ticks',
                         'shown_ns', 'y', 'full',
                         'done', 'steps', 'params', 'bounds', 'origins', 'valid_delta', 'warned',
                         'described'):
                array = getattr(self, name)
                array[k] = array[last]
            moved.slot = k
            self.rows[k] = moved
        self.rows.pop()
        del self.entities[entity.name]
        self.version += 1
        self.rows_version += 1

    def select(
        self,
        pattern=None,
        tags: tuple[str, ...] = (),
        all_tags: bool = False,
        sphere: tuple[np.ndarray, float] | None = None,
        box: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> list[Entity]:
        """
        Return the entities that pass every filter given.

        Name matching ``pattern`` (an object with ``search(name)``, e.g. from
        :func:`football_ros.simulation.names.compile_filter`; a string is compiled by it), any
        (``all_tags``: all) of ``tags`` (see :meth:`tags`), the ball overlapping the ``sphere``
        (centre [m], radius [m]) or the axis-aligned ``box`` (two corners [m]).
        """
        if isinstance(pattern, str):
            try:
                pattern = names.compile_filter(pattern)
            except names.FilterError as exc:
                raise EntityError('filter', str(exc)) from None
        out = []
        for entity in self.rows:
            if pattern is not None and not pattern.search(entity.name):
                continue
            if tags:
                have = set(self.tags(entity))
                hits = [t in have for t in tags]
                if not (all(hits) if all_tags else any(hits)):
                    continue
            if sphere is not None or box is not None:
                position = entity.state()[0]
                reach = 0.5 * PRESETS[entity.ball_name].length
                if sphere is not None:
                    centre, radius = sphere
                    if float(np.linalg.norm(position - centre)) > radius + reach:
                        continue
                if box is not None:
                    lo, hi = np.minimum(*box), np.maximum(*box)
                    nearest = np.clip(position, lo, hi)
                    if float(np.linalg.norm(position - nearest)) > reach:
                        continue
            out.append(entity)
        return out

    @staticmethod
    def tags(entity: Entity) -> list[str]:
        """Return an entity's tags: its ball preset and 'football_ros'."""
        return [entity.ball_name, 'football_ros']

    def runs(self) -> list[tuple[Entity, FlightRun]]:
        """Entities with a flight run, in row order (the default first)."""
        return [(e, e.run) for e in self.rows if e.run is not None]

    def place(self, entity: Entity, position, orientation) -> None:
        """Put ``entity`` at rest at a pose (its flight, if any, is dropped)."""
        self._rest(entity, check_pose(position, orientation))

    def throw(self, entity: Entity, run: FlightRun) -> None:
        """Make ``entity`` fly ``run`` from its release on (its previous flight is dropped)."""
        flight, k = run.flight, entity.slot
        if run.bounds is None:
            run.bounds = runaway_bounds(flight)
        run.entity, entity.run = entity, run
        self.y[k] = self.full[k] = flight.y0
        self.done[k], self.steps[k], self.params[k] = 0, flight.step, flight.params
        self.bounds[k], self.origins[k] = run.bounds, flight.initial.position
        self.flown[k] = self.next_t[k] = self.tick_base[k] = 0.0
        self.ticks[k] = 0
        self.status[k], self.warned[k] = FLYING, False
        self.valid_delta[k] = max_valid_delta(flight.model, flight.moment, flight.aero)
        self.pose[k, :3] = flight.initial.position
        self.pose[k, 3:] = flight.initial.attitude
        self.twist[k] = 0.0
        self.version += 1

    def end_all(self, reason: str) -> int:
        """End every flight in the air with an ERROR event; return how many."""
        rows = self.flying()
        for k in rows:
            run = self.rows[k].run
            self.status[k] = ENDED
            text = run.end(reason)
            if text:
                self.events.append(('ERROR', 'error', text, run.label))
        self.version += 1
        return int(rows.size)

    def flying(self) -> np.ndarray:
        """Rows of the balls in the air."""
        return np.flatnonzero(self.status[:self.size] == FLYING)

    def compute(self, slots: np.ndarray, times: np.ndarray) -> Computed:
        """
        Integrate rows ``slots`` to flight times ``times`` [s] (one kernel call), uncommitted.

        Only whole steps are committed to ``y`` (as :meth:`Flight.state_at` does), so a pass
        may be computed ahead and thrown away: the next pass to the same times gives the same.
        """
        n = slots.size
        states, done = self.y[slots], self.done[slots]
        out = np.empty((n, dyn.N_STATE))
        described = np.empty((n, dyn.N_DESCRIBE))
        landing = np.empty(n)
        if n:
            kernel.advance_many(states, done, self.steps[slots], self.params[slots], times, 0.0,
                                out, described, landing)
            self.y[slots], self.done[slots] = states, done
        fine = kernel.runaway_free(out, described, landing, times, self.bounds[slots],
                                   self.origins[slots], MAX_DISTANCE_M, MAX_FLIGHT_S)
        return Computed(self.version, slots, times, out, described, landing, fine)

    def commit(self, c: Computed, wall_ns: int) -> np.ndarray:
        """
        Judge and keep a computed pass; return the rows that show a new state.

        The guard (a runaway ends the flight, ERROR), the landing (OK) and the data range (WARN,
        once a flight) are queued as events; nothing else costs per-ball Python work.
        """
        if not c.slots.size:
            return c.slots
        keep = np.ones(c.slots.size, dtype=bool)
        for j in np.flatnonzero(~c.fine):  # the compiled guard fired: the exact rule decides
            entity = self.rows[c.slots[j]]
            problem = entity.run.runaway(self._sample(c, j))
            if problem:
                keep[j] = False
                self.status[c.slots[j]] = ENDED
                text = entity.run.end(problem)
                if text:
                    self.events.append(('ERROR', 'error', text, entity.run.label))
        slots, out, described = c.slots[keep], c.out[keep], c.described[keep]
        landing = c.landing[keep]
        self.flown[slots] = np.where(np.isnan(landing), c.times[keep], landing)
        self.full[slots] = out
        self.described[slots] = described
        self.pose[slots, :3] = out[:, dyn.R:dyn.R + 3]
        self.pose[slots, 3:] = described[:, dyn.D_ORIENT:dyn.D_ORIENT + 4]
        self.twist[slots, :3] = out[:, dyn.V:dyn.V + 3]
        self.twist[slots, 3:] = described[:, dyn.D_OMEGA:dyn.D_OMEGA + 3]
        for k in slots[~np.isnan(landing)]:
            entity = self.rows[k]
            self.status[k], self.shown_ns[k] = LANDED, wall_ns
            entity.run.landing = sample = self.sample_of(entity)
            self.events.append(('OK', 'landed', f"flight '{entity.run.label}' "
                                + landed_text(sample.position, sample.t), entity.run.label))
        left = (described[:, dyn.D_DELTA] > self.valid_delta[slots]) & ~self.warned[slots]
        for k in slots[left]:
            self.warned[k] = True
            run = self.rows[k].run
            text = run.validity_text(self.sample_of(self.rows[k]))
            self.events.append(('WARN', 'validity', text, run.label))
        return slots

    def fly(self, dt: float, wall_ns: int, ahead: Computed | None = None) -> np.ndarray:
        """
        Show every ball in the air at its next time, then move that on by ``dt`` [s] of flight.

        One real-time tick; returns the rows shown (a pass computed ahead is used if current).
        """
        slots = self.flying()
        if (ahead is None or ahead.version != self.version
                or not np.array_equal(ahead.slots, slots)):
            ahead = self.compute(slots, self.next_t[slots])
        shown = self.commit(ahead, wall_ns)
        if dt != self._tick_dt:  # a new rate or real-time factor: count the ticks from here
            n = self.size
            self.tick_base[:n], self.ticks[:n], self._tick_dt = self.next_t[:n], 0, dt
        self.ticks[slots] += 1  # the next time as base + ticks x dt: no sum of round-offs
        self.next_t[slots] = self.tick_base[slots] + self.ticks[slots] * dt
        return shown

    def ahead(self) -> Computed:
        """Compute the next tick's pass now (see :meth:`fly`)."""
        slots = self.flying()
        return self.compute(slots, self.next_t[slots])

    def advance(self, n_steps: int, step: float, wall_ns: int) -> np.ndarray:
        """
        Lock-step: every ball in the air ``n_steps`` integration steps of ``step`` [s] on.

        Returns the rows shown; the next real-time tick shows the same time.
        """
        slots = self.flying()
        times = self.next_t[slots] + n_steps * step
        shown = self.commit(self.compute(slots, times), wall_ns)
        self.next_t[slots] = self.tick_base[slots] = times
        self.ticks[slots] = 0
        return shown

    def step(self, n_steps: int, step: float, wall_ns: int) -> list[tuple[Entity, BallSample]]:
        """
        :meth:`advance`, then (entity, sample) for every flight the guard has not ended.

        At its new time, or its landing.
        """
        self.advance(n_steps, step, wall_ns)
        return [(e, self.sample_of(e)) for e, run in self.runs() if run.ended is None]

    def due(self, wall_ns: int, hold_rate: float, landed: bool = True) -> np.ndarray:
        """
        Rows whose resting state this tick shows again (and count them as shown).

        At rest (a spawned ball) or ``landed``: at once after a spawn, place or reset, then
        every 1 / ``hold_rate`` [s] of wall time ``wall_ns`` (0 = only once). The default
        entity at rest is not shown.
        """
        n = self.size
        status, shown = self.status[:n], self.shown_ns[:n]
        if n == 1 and status[0] != LANDED:  # the default ball alone, not landed: nothing
            return np.empty(0, dtype=np.int64)
        resting = self._resting(landed)
        if hold_rate > 0:
            ready = (shown < 0) | (wall_ns - shown >= 1e9 / hold_rate)
        else:
            ready = shown < 0
        rows = np.flatnonzero(resting & ready)
        shown[rows] = wall_ns
        return rows

    def next_due_ns(self, hold_rate: float, landed: bool = True) -> int | None:
        """
        Wall time [ns] from which :meth:`due` returns a row again; None: not until a change.

        The same rules as :meth:`due` (a row never shown: due at once, returned as 0).
        """
        shown = self.shown_ns[:self.size]
        resting = self._resting(landed)
        if not resting.any():
            return None
        if (shown[resting] < 0).any():
            return 0
        if hold_rate <= 0:
            return None
        return int(shown[resting].min() + math.ceil(1e9 / hold_rate))

    def _resting(self, landed: bool) -> np.ndarray:
        """Rows a tick may show at rest: spawned balls at rest, and landed ones if ``landed``."""
        status = self.status[:self.size]
        resting = (status == AT_REST) | ((status == LANDED) if landed else False)
        resting[0] &= status[0] == LANDED  # the default entity at rest is not shown
        return resting

    def _sample(self, c: Computed, j: int) -> BallSample:
        out, d = c.out[j], c.described[j]
        landed = not math.isnan(c.landing[j])
        return _sample(float(c.landing[j]) if landed else float(c.times[j]), out, d, landed)

    def sample_of(self, entity: Entity) -> BallSample:
        """Return the latest state of ``entity`` as a sample (theory angles NaN: ShownSample)."""
        k = entity.slot
        return _sample(float(self.flown[k]), self.full[k], self.described[k],
                       self.status[k] == LANDED)

    def reset(self, state: bool, spawned: bool) -> list[Entity]:
        """
        Reset the entities (the clock is the user's); return the entities deleted.

        ``spawned`` deletes every spawned entity; ``state`` puts every entity back at rest at
        its spawn pose (flights dropped).
        """
        doomed = [e for e in self.rows if e.spawned] if spawned else []
        for entity in doomed:
            self._remove(entity)
        if state:
            for entity in self.rows:
                self._rest(entity, entity.spawn_pose)
        return doomed


class ShownSample:
    """
    A flying ball's sample as one frame shows it, built when first read.

    The quasi-steady theory advances at once (its integrals follow every frame shown); the
    sample (with the linear theory's closed form, the larger part of its cost) is built only
    if ``sample`` is read, e.g. when one of the ball's state topics has a subscriber or a
    marker is due. ``t`` [s] the flight time shown, ``landed`` by then.
    """

    def __init__(self, world: 'World', entity: 'Entity') -> None:
        k = entity.slot
        self.t = float(world.flown[k])
        self.landed = bool(world.status[k] == LANDED)
        self._y, self._d = world.full[k].copy(), world.described[k].copy()
        self._flight = entity.run.flight
        self._quasi = self._flight.quasi_steady_angles(self.t, self._y)
        self._sample: BallSample | None = None

    @property
    def sample(self) -> BallSample:
        """Return the ball then, with both theories' angles."""
        if self._sample is None:
            theory = (self._flight.linear_angles(self.t), self._quasi)
            self._sample = _sample(self.t, self._y, self._d, self.landed, theory)
        return self._sample


def _sample(t: float, y: np.ndarray, d: np.ndarray, landed: bool, theory=None) -> BallSample:
    linear, quasi = theory if theory is not None else (np.full(2, np.nan), np.full(2, np.nan))
    return BallSample(
        t=t,
        position=y[dyn.R:dyn.R + 3].copy(),
        velocity=y[dyn.V:dyn.V + 3].copy(),
        orientation=d[dyn.D_ORIENT:dyn.D_ORIENT + 4].copy(),
        axis=d[dyn.D_AXIS:dyn.D_AXIS + 3].copy(),
        angular_velocity=d[dyn.D_OMEGA:dyn.D_OMEGA + 3].copy(),
        aero_angles=d[dyn.D_ALPHA:dyn.D_DELTA + 1].copy(),
        aero_angles_linear=linear,
        landed=bool(landed),
        aero_angles_quasi_steady=quasi,
    )


def _brief(value, limit: int = 64) -> str:
    text = repr(value) if not isinstance(value, str) else value
    text = ''.join(c if c.isprintable() else '?' for c in text)
    return text if len(text) <= limit else text[:limit] + '...'
