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
Compile ahead: load (or compile, first time) every numba kernel the nodes and commands use.

:func:`compile_ahead` runs each compiled entry point once on the argument types the package
passes it (float64 arrays, Python floats), so that numba's on-disk cache holds them and a later
process only loads them. Where the cache lives: numba's ``__pycache__`` beside the sources, or
the ``NUMBA_CACHE_DIR`` that :mod:`football_ros` chose when the package folder is read-only
(a colcon install): see :func:`football_ros.numba_cache_dir`.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib
import pkgutil
import time
from typing import Callable


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


def kernels() -> dict[str, object]:
    """
    Return every numba dispatcher of :mod:`football_ros.physics`, by ``module.name``.

    Functions inlined into their callers are not compiled on their own.
    """
    from numba.core.registry import CPUDispatcher

    from . import __path__ as package_path

    out = {}
    for info in pkgutil.iter_modules(package_path):
        module = importlib.import_module(f'{__package__}.{info.name}')
        for attr, value in vars(module).items():
            if (
                isinstance(value, CPUDispatcher)
                and value.__module__ == module.__name__
                and value.targetoptions.get('inline', 'never') != 'always'
            ):
                out[f'{info.name}.{attr}'] = value
    return out


def _counts() -> tuple[int, int]:
    hits = misses = 0
    for dispatcher in kernels().values():
        stats = dispatcher.stats
        hits += sum(stats.cache_hits.values())
        misses += sum(stats.cache_misses.values())
    return hits, misses


def compile_ahead(progress: Callable[[str], None] | None = None) -> list[CompileStep]:
    """
    Load or compile every kernel the nodes and commands use; returns one entry per stage.

    ``progress`` (e.g. ``print``) gets one line as each stage starts and ends. Pure: no ROS.
    About a minute on two cores the first time after an install, well under a second after.
    """
    say = progress or (lambda _line: None)
    steps = []
    hits, misses = _counts()
    for i, (name, run) in enumerate(STEPS, 1):
        say(f'[{i}/{len(STEPS)}] {name} ...')
        start = time.perf_counter()
        run()
        seconds = time.perf_counter() - start
        new_hits, new_misses = _counts()
        step = CompileStep(name, seconds, new_hits - hits, new_misses - misses)
        hits, misses = new_hits, new_misses
        how = (
            f'compiled {step.compiled} kernel(s)'
            if step.compiled
            else f'loaded {step.loaded} kernel(s) from the cache'
        )
        say(f'[{i}/{len(STEPS)}] {name}: {how} in {seconds:.1f} s')
        steps.append(step)
    return steps


def uncovered() -> list[str]:
    """
    Kernels with no compiled version in this process.

    After :func:`compile_ahead` on a cold cache none may be left (on a warm cache, the kernels
    a cached caller calls load inside it and are listed here).
    """
    return sorted(name for name, d in kernels().items() if not d.signatures)
