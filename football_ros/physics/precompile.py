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
Compile ahead: load (or compile, first time) the physics kernels the nodes and commands use.

:func:`compile_ahead` runs each compiled entry point once on the argument types the package
passes it (float64 arrays, Python floats), so that numba's on-disk cache holds them and a later
process only loads them. The layers above add their own steps through ``steps`` and
``places`` (:mod:`football_ros.tools.compile` lists every kernel of the package). Where the
cache lives: numba's ``__pycache__`` beside the sources, or the ``NUMBA_CACHE_DIR`` that
:mod:`football_ros` chose when the package folder is read-only (a colcon install): see
:func:`football_ros.numba_cache_dir`.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib
import pkgutil
import time
from types import ModuleType
from typing import Callable, Sequence


@dataclass(frozen=True)
class CompileStep:
    """
    One stage of :func:`compile_ahead`.

    What it loaded, how long it took [s], how many kernel versions came from the disk cache and
    how many had to be compiled.
    """

    name: str
    seconds: float
    loaded: int
    compiled: int


def _single_flight() -> None:
    from .flight import Flight
    from .release import Release

    for model in ('paper', 'full'):
        Flight.from_release(Release(model=model)).simulate(rate=100.0, duration=10.0)


def _real_time() -> None:
    from . import dynamics
    from .flight import Flight
    from .release import Release

    flight = Flight.from_release(Release())
    flight.sample(0.0105)
    flight.sample(10.0)  # past the landing: the landing search
    dynamics.advance(flight.y0.copy(), 1, flight.step, flight.params)


def _batch() -> None:
    import numpy as np

    from .batch import simulate_batch
    from .presets import get_preset
    from .release import release_states

    states = release_states(
        np.array([27.4, 20.0]), 30.0, 0.0, 600.0, 0.0, 0.0, 0.0, 0.0, np.zeros(3)
    )
    ball = get_preset('american')
    simulate_batch(ball, states, 'full')
    probe = simulate_batch(ball, states, sample_count=1)
    simulate_batch(ball, states, sample_period=probe.sample_period, sample_count=2)


STEPS: tuple[tuple[str, Callable[[], None]], ...] = (
    ('single-flight kernel (RK4, landing search)', _single_flight),
    ('real-time sampling (state_at, describe)', _real_time),
    ('batch kernel (DOP853, parallel)', _batch),
)


def kernels(places: Sequence[ModuleType] = ()) -> dict[str, object]:
    """
    Return every numba dispatcher of the ``places`` (default: :mod:`football_ros.physics`).

    A place is a package (all its modules) or a module. Keyed by ``package.module.name`` below
    :mod:`football_ros`. Functions inlined into their callers are not compiled on their own.
    """
    from numba.core.registry import CPUDispatcher

    modules = []
    for place in places or (importlib.import_module(__package__),):
        if hasattr(place, '__path__'):
            modules += [
                importlib.import_module(f'{place.__name__}.{info.name}')
                for info in pkgutil.iter_modules(place.__path__)
            ]
        else:
            modules.append(place)
    out = {}
    for module in modules:
        for attr, value in vars(module).items():
            if (
                isinstance(value, CPUDispatcher)
                and value.__module__ == module.__name__
                and value.targetoptions.get('inline', 'never') != 'always'
            ):
                out[f'{module.__name__.partition(".")[2]}.{attr}'] = value
    return out


def cache_counts(places: Sequence[ModuleType] = ()) -> tuple[int, int]:
    """(versions loaded from numba's disk cache, versions compiled) so far in this process."""
    hits = misses = 0
    for dispatcher in kernels(places).values():
        stats = dispatcher.stats
        hits += sum(stats.cache_hits.values())
        misses += sum(stats.cache_misses.values())
    return hits, misses


def compile_ahead(
    progress: Callable[[str], None] | None = None,
    steps: Sequence[tuple[str, Callable[[], object]]] = STEPS,
    places: Sequence[ModuleType] = (),
) -> list[CompileStep]:
    """
    Load or compile the kernels ``steps`` run (default: the physics'); one entry per step.

    ``places``: where the counted kernels live (packages or modules; default: the physics).
    ``progress`` (e.g. ``print``) gets one line as each step starts and ends. Pure: no ROS.
    """
    say = progress or (lambda _line: None)
    done = []
    hits, misses = cache_counts(places)
    for i, (name, run) in enumerate(steps, 1):
        say(f'[{i}/{len(steps)}] {name} ...')
        start = time.perf_counter()
        run()
        seconds = time.perf_counter() - start
        new_hits, new_misses = cache_counts(places)
        step = CompileStep(name, seconds, new_hits - hits, new_misses - misses)
        hits, misses = new_hits, new_misses
        how = (
            f'compiled {step.compiled} kernel(s)'
            if step.compiled
            else f'loaded {step.loaded} kernel(s) from the cache'
        )
        say(f'[{i}/{len(steps)}] {name}: {how} in {seconds:.1f} s')
        done.append(step)
    return done


def uncovered(places: Sequence[ModuleType] = ()) -> list[str]:
    """
    Kernels of the ``places`` (default: the physics) with no compiled version in this process.

    After :func:`compile_ahead` on a cold cache none may be left (on a warm cache, the kernels
    a cached caller calls load inside it and are listed here).
    """
    return sorted(name for name, d in kernels(places).items() if not d.signatures)
