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

:class:`FlightRun` is one flight in the air with its bookkeeping: the time flown (ticks of
``tick_dt`` simulated seconds since the last rebase, plus the time flown before it), the
runaway guard, the data-range check, the landed detection and the trail of the markers.
:class:`World` holds the entities by name (the default entity ``football`` always exists; the
others are spawned, up to a limit), validates names and poses, filters entities, advances
every flight in lock-step by whole integration steps and resets; what happens is queued as
events (level, event, text) for /diagnostics, at most ``MAX_EVENTS`` of them.

The world is not thread-safe: its user (the simulator node) holds one lock around changes.
Everything is in ``field`` and SI.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass, field
import math
import re

import numpy as np

from . import kernel
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
MAX_FILTER_CHARS = 256
"""Longest name filter (regular expression) of :meth:`World.select`."""
URI_SCHEME = 'football_ros://'
"""Spawnable URIs: this scheme and a ball preset (``football_ros://american``)."""
MAX_POSITION_M = 1.0e4
"""Largest coordinate of a spawn or entity pose [m]."""
_NESTED_QUANTIFIER = re.compile(r'\)\s*[*+?{]')


class EntityError(ValueError):
    """A refused world operation; ``reason`` names the kind (the node maps it to a code)."""

    def __init__(self, reason: str, text: str) -> None:
        super().__init__(text)
        self.reason = reason


class Events(collections.deque):
    """Bounded event queue (level, event, message); counts what it had to drop."""

    def __init__(self) -> None:
        super().__init__(maxlen=MAX_EVENTS)
        self.dropped = 0

    def append(self, item) -> None:
        if len(self) == self.maxlen:
            self.dropped += 1
        super().append(item)


@dataclass
class FlightRun:
    """
    One flight in the air and its bookkeeping.

    ``label`` names it in events (the release's id), ``order`` is whatever the user built it
    from (opaque here).
    """

    label: str
    flight: Flight
    order: object = None
    ticks: int = 0
    tick_dt: float = 0.0  # simulated seconds per tick for this run
    time_offset: float = 0.0  # simulated seconds flown before the last rebase
    landed_reported: bool = False
    last_hold_ns: int = 0
    last_marker_ns: int | None = None
    trail: collections.deque = field(default_factory=lambda: collections.deque(maxlen=500))
    trail_count: int = 0  # positions ever appended to the trail
    ended: str | None = None  # why the guard ended the flight (ERROR), None while fine
    linear_diverged: bool = False  # the linear prediction overflowed (unstable ball)
    bounds: tuple[float, float] | None = None  # runaway speed [m/s] and rate [rad/s]
    valid_delta: float | None = None  # largest total angle inside the data ranges [rad]
    validity_warned: bool = False  # the flight left a data range (warned once)
    # Integrated by the world's kernel (spawned balls) instead of Flight.sample: the committed
    # state after ``done`` whole steps, and the landing sample once landed.
    batched: bool = False
    y: np.ndarray | None = None
    done: int = 0
    landing: BallSample | None = None
    cleared: BallSample | None = None  # the sample the batch guard found fine (judge skips)

    @property
    def time(self) -> float:
        """Return the simulated seconds flown since the release."""
        return self.time_offset + self.ticks * self.tick_dt

    @property
    def flying(self) -> bool:
        """In the air: neither landed (reported) nor ended by the guard."""
        return self.ended is None and not self.landed_reported

    def rebase(self, tick_dt: float, trail_length: int) -> None:
        """Keep the time flown and go on with ``tick_dt`` [s] of flight per tick."""
        self.time_offset, self.ticks = self.time, 0
        self.tick_dt = tick_dt
        if self.trail.maxlen != max(trail_length, 1):
            self.trail = collections.deque(self.trail, maxlen=max(trail_length, 1))

    def select(self, wall_ns: int, hold_rate: float) -> float | None:
        """
        Return the flight time [s] this tick publishes (and count the tick), or None.

        None once ended, and for a landed ball except every 1 / ``hold_rate`` [s] of wall
        time (``wall_ns``), when the landed state is held.
        """
        if self.ended is not None:
            return None
        if self.landed_reported:
            if hold_rate <= 0 or wall_ns - self.last_hold_ns < 1e9 / hold_rate:
                return None
            self.last_hold_ns = wall_ns
        t = self.time
        self.ticks += 1
        return t

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

    def left_validity(self, sample: BallSample) -> str | None:
        """
        Return the warning text the first time the total angle leaves a data range, else None.

        The text lists :func:`football_ros.physics.aero.out_of_validity` (once per flight).
        """
        if self.validity_warned:
            return None
        flight = self.flight
        if self.valid_delta is None:
            self.valid_delta = max_valid_delta(flight.model, flight.moment, flight.aero)
        delta = float(sample.aero_angles[2])
        if delta <= self.valid_delta:
            return None
        self.validity_warned = True
        return (
            f"flight '{self.label}' left the data range at t = {sample.t:.3f} s: "
            + '; '.join(
                out_of_validity(delta, flight.model, flight.moment, flight.aero, flight.ball)
            )
        )

    def mark_landed(self, sample: BallSample, wall_ns: int) -> str | None:
        """Return the landed event's text when ``sample`` is the landing (once), else None."""
        if not sample.landed or self.landed_reported:
            return None
        self.landed_reported, self.last_hold_ns = True, wall_ns
        return f"flight '{self.label}' " + landed_text(sample.position, sample.t)

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


@dataclass
class Entity:
    """
    A ball in the world: at rest at ``rest_pose`` or flying ``run``.

    ``rest_pose``: (position [m], orientation x, y, z, w) in ``field``, the spawn pose (or
    where SetEntityState put it at rest). ``last``: the latest sample of the run.
    """

    name: str
    ball_name: str
    rest_pose: tuple[np.ndarray, np.ndarray]
    spawned: bool = True
    run: FlightRun | None = None
    last: BallSample | None = None
    spawn_pose: tuple[np.ndarray, np.ndarray] | None = None
    rest_shown_ns: int | None = None  # wall time its rest pose was last published; None: due

    @property
    def uri(self) -> str:
        return URI_SCHEME + self.ball_name

    def rest_due(self, wall_ns: int, hold_rate: float) -> bool:
        """
        Tell whether this tick publishes the rest pose (and count it as published).

        At rest only: at once after a spawn, place or reset, then every 1 / ``hold_rate`` [s]
        of wall time ``wall_ns`` (0 = only once), as a landed ball is held.
        """
        if self.run is not None:
            return False
        last = self.rest_shown_ns
        if last is not None and (hold_rate <= 0 or wall_ns - last < 1e9 / hold_rate):
            return False
        self.rest_shown_ns = wall_ns
        return True

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position [m], orientation (x, y, z, w), velocity [m/s], angular velocity [rad/s]."""
        sample = self.last if self.run is not None else None
        if sample is None:
            position, orientation = self.rest_pose
            return position.copy(), orientation.copy(), np.zeros(3), np.zeros(3)
        if sample.landed:  # at rest on the ground
            return sample.position, sample.orientation, np.zeros(3), np.zeros(3)
        return sample.position, sample.orientation, sample.velocity, sample.angular_velocity

    @property
    def condition(self) -> str:
        """'at rest', 'flying', 'landed' or 'ended' (the guard ended its flight)."""
        run = self.run
        if run is None:
            return 'at rest'
        if run.ended is not None:
            return 'ended'
        if run.landed_reported or (self.last is not None and self.last.landed):
            return 'landed'
        return 'flying'


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


class World:
    """
    Named entities (balls), the default one included, at most ``max_entities`` of them.

    Names follow :data:`NAME_PATTERN`; the default entity cannot be deleted.
    """

    def __init__(self, max_entities: int = 100, default_ball: str = 'american') -> None:
        self.max_entities = max(1, int(max_entities))
        self.events = Events()
        self.entities: dict[str, Entity] = {}
        self._default_ball = default_ball
        self._add_default()
        self._counter = 0
        self._batch: tuple | None = None  # (runs, their y, arrays) of the last kernel call

    def _add_default(self) -> None:
        rest = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        self.entities[DEFAULT_ENTITY] = Entity(
            DEFAULT_ENTITY, self._default_ball, rest, spawned=False, spawn_pose=rest
        )

    @property
    def default(self) -> Entity:
        return self.entities[DEFAULT_ENTITY]

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
        entity = Entity(name, ball, pose, spawned=True, spawn_pose=pose)
        self.entities[name] = entity
        return entity

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
        del self.entities[name]
        return entity

    def select(
        self,
        pattern: str = '',
        tags: tuple[str, ...] = (),
        all_tags: bool = False,
        sphere: tuple[np.ndarray, float] | None = None,
        box: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> list[Entity]:
        """
        Return the entities that pass every filter given.

        Name matching ``pattern`` (a regular expression, searched), any (``all_tags``: all)
        of ``tags`` (see :meth:`tags`), the ball overlapping the ``sphere`` (centre [m],
        radius [m]) or the axis-aligned ``box`` (two corners [m]).

        Raises EntityError('filter') for a bad or too costly pattern (groups followed by a
        quantifier are refused: they can backtrack exponentially).
        """
        regex = None
        if pattern:
            if len(pattern) > MAX_FILTER_CHARS or _NESTED_QUANTIFIER.search(pattern):
                raise EntityError(
                    'filter',
                    f'filter must be a regular expression of at most {MAX_FILTER_CHARS} '
                    'characters without a quantified group',
                )
            try:
                regex = re.compile(pattern)
            except (re.error, RecursionError, OverflowError) as exc:
                raise EntityError('filter', f'filter is not a regular expression: {exc}') from None
        out = []
        for entity in self.entities.values():
            if regex is not None and not regex.search(entity.name):
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
        """Entities with a flight run, in order (the default first)."""
        return [(e, e.run) for e in self.entities.values() if e.run is not None]

    def place(self, entity: Entity, position, orientation) -> None:
        """Put ``entity`` at rest at a pose (its flight, if any, is dropped)."""
        entity.rest_pose = check_pose(position, orientation)
        entity.run, entity.last, entity.rest_shown_ns = None, None, None

    def throw(self, entity: Entity, run: FlightRun) -> None:
        """
        Make ``entity`` fly ``run`` from now on (its previous flight is dropped).

        A spawned entity's run is integrated by :func:`kernel.advance_many` (pose and twist
        only); the default entity's by :meth:`Flight.sample` (with the linear theory's
        angles, which its topics carry).
        """
        run.batched = entity.spawned
        if run.batched:
            run.y, run.done, run.landing = run.flight.y0.copy(), 0, None
        entity.run, entity.last = run, None

    def sample(self, items: list[tuple[FlightRun, float]]) -> list[BallSample]:
        """
        Sample each run at its flight time [s] (never decreasing between calls per run).

        Batched runs go through one :func:`kernel.advance_many` call; their samples carry no
        linear-theory angles (NaN).
        """
        out: list[BallSample | None] = [None] * len(items)
        batch = []
        for k, (run, t) in enumerate(items):
            if not run.batched:
                out[k] = run.flight.sample(t)
            elif run.landing is not None:
                out[k] = run.landing
            else:
                batch.append(k)
        if batch:
            runs = [items[k][0] for k in batch]
            states, steps, params, bounds, origins = self._batch_arrays(runs)
            done = np.array([r.done for r in runs], dtype=np.int64)
            times = np.array([items[k][1] for k in batch], dtype=float)
            n = len(batch)
            new = np.empty_like(states)
            described = np.empty((n, dyn.N_DESCRIBE))
            landing_times = np.empty(n)
            kernel.advance_many(
                states, done, steps, params, times, 0.0, new, described, landing_times
            )
            fine = kernel.runaway_free(new, described, landing_times, times, bounds, origins,
                                       MAX_DISTANCE_M, MAX_FLIGHT_S)
            nan2 = np.full(2, np.nan)
            for j, (k, run) in enumerate(zip(batch, runs)):
                run.done = int(done[j])  # run.y: row j of states, advanced in place
                landed = not math.isnan(landing_times[j])
                d = described[j]
                sample = BallSample(  # views of this call's arrays: nothing else writes them
                    t=float(landing_times[j]) if landed else float(times[j]),
                    position=new[j, dyn.R:dyn.R + 3],
                    velocity=new[j, dyn.V:dyn.V + 3],
                    orientation=d[dyn.D_ORIENT:dyn.D_ORIENT + 4],
                    axis=d[dyn.D_AXIS:dyn.D_AXIS + 3],
                    angular_velocity=d[dyn.D_OMEGA:dyn.D_OMEGA + 3],
                    aero_angles=d[dyn.D_ALPHA:dyn.D_DELTA + 1],
                    aero_angles_linear=nan2,
                    landed=landed,
                    aero_angles_quasi_steady=nan2,
                )
                run.cleared = sample if fine[j] else None
                if landed:
                    run.landing = sample
                out[k] = sample
        return out

    def _batch_arrays(self, runs: list[FlightRun]) -> tuple:
        """
        Return the kernel's arrays of ``runs``: states, steps, params, runaway bounds, origins.

        Kept from the last call while the same runs come in the same order, each run's ``y``
        still the row it was given (the kernel advances the rows in place); else stacked anew
        and each ``y`` made a view of its row.
        """
        last = self._batch
        if last is not None and len(last[0]) == len(runs) and all(
                a is b and a.y is y for a, b, y in zip(runs, last[0], last[1])):
            return last[2]
        for run in runs:
            if run.bounds is None:
                run.bounds = runaway_bounds(run.flight)
        states = np.stack([run.y for run in runs])
        for j, run in enumerate(runs):
            run.y = states[j]
        arrays = (
            states,
            np.array([run.flight.step for run in runs]),
            np.stack([run.flight.params for run in runs]),
            np.array([run.bounds for run in runs]),
            np.array([run.flight.initial.position for run in runs]),
        )
        self._batch = (list(runs), [run.y for run in runs], arrays)
        return arrays

    def judge(self, entity: Entity, run: FlightRun, sample: BallSample, wall_ns: int) -> bool:
        """
        Apply the guard, the landing and the data-range check to a new sample of a run.

        Queues the events; returns False when the guard ended the flight (the sample must not
        be published), else True (``entity.last`` is then the sample).
        """
        problem = None if run.cleared is sample else run.runaway(sample)
        if problem:
            text = run.end(problem)
            if text:
                self.events.append(('ERROR', 'error', text))
            return False
        entity.last = sample
        text = run.mark_landed(sample, wall_ns)
        if text:
            self.events.append(('OK', 'landed', text))
        warning = run.left_validity(sample)
        if warning:
            self.events.append(('WARN', 'validity', warning))
        return True

    def step(self, n_steps: int, step: float, wall_ns: int) -> list[tuple[Entity, BallSample]]:
        """
        Advance every flight in the air by exactly ``n_steps`` integration steps of ``step`` [s].

        Returns (entity, sample) for every entity with a run the guard has not ended, at its
        new time (a landed ball: its landing). Guard, landing and data-range events are
        queued as in real time.
        """
        moving, out = [], []
        for entity, run in self.runs():
            if run.ended is not None:
                continue
            if run.landed_reported:
                out.append((entity, entity.last))
                continue
            run.time_offset, run.ticks = run.time + n_steps * step, 0
            moving.append((entity, run))
        samples = self.sample([(run, run.time) for _entity, run in moving])
        for (entity, run), sample in zip(moving, samples):
            if self.judge(entity, run, sample, wall_ns):
                out.append((entity, sample))
        return out

    def reset(self, state: bool, spawned: bool) -> None:
        """
        Reset the entities (the clock is the user's).

        ``spawned`` deletes every spawned entity; ``state`` puts every entity back at rest at
        its spawn pose (flights dropped).
        """
        if spawned:
            for name in [n for n, e in self.entities.items() if e.spawned]:
                del self.entities[name]
        if state:
            for entity in self.entities.values():
                entity.rest_pose = entity.spawn_pose
                entity.run, entity.last, entity.rest_shown_ns = None, None, None


def _brief(value, limit: int = 64) -> str:
    text = repr(value) if not isinstance(value, str) else value
    text = ''.join(c if c.isprintable() else '?' for c in text)
    return text if len(text) <= limit else text[:limit] + '...'
