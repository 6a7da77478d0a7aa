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
Learn to throw 40 m with the cross-entropy method on the vector env (numpy only).

    python examples/learn_to_throw.py [--seed 0] [--budget 100000] [--figure FILE.png]

The task: a target 40 m straight ahead at the hand's height (1.8 m), the full model, release
noise a tenth of the default thrower's (:data:`football_ros.physics.release.ERROR_SIGMAS`: at
the default noise no release puts 90 % within 1 m at 40 m, the speed error alone spreads the
range by about 2 m). The policy is one release (the 8 action components); the cross-entropy
method draws a population of releases from a Gaussian, throws each once (with noise), keeps the
best tenth and refits the Gaussian to them (smoothed); it starts from the ball's nominal pass
(27.4 m/s, 30 deg, 600 rpm) with a quarter of each action's range as its spread. After every
generation the mean release is thrown ``EVAL`` times; at 90 % within 1 m it is thrown
``CONFIRM`` more times, and the learning stops if those make 90 % too. The learning curve is
the fraction within 1 m against the throws spent (every throw counted: population,
evaluations, confirmations); it stops at the goal or when the budget is spent (exit status 1
then).
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

import football_ros.envs  # noqa: F401  (registers the environments)
from football_ros.physics.presets import get_preset
import gymnasium as gym
import numpy as np

TARGET = {'target_distance': (40.0, 40.0), 'target_bearing_deg': (0.0, 0.0),
          'target_height': (1.8, 1.8), 'release_noise': 0.1}
POPULATION = 500
ELITE = 50
SMOOTHING = 0.7  # weight of the elite's fit in the new Gaussian
EVAL = 200
CONFIRM = 5000
GOAL = 0.9
RADIUS = 1.0  # m


def _vec(n: int, seed: int):
    env = gym.make_vec('football_ros/Throw-v0', num_envs=n,
                       vectorization_mode='vector_entry_point', **TARGET)
    env.reset(seed=seed)
    return env


def cross_entropy(seed: int, budget: int) -> tuple[np.ndarray, list[tuple[int, float, float]]]:
    """Return the learned release and its curve [(throws spent, within 1 m, median miss)]."""
    population, evaluation, confirmation = _vec(POPULATION, seed), _vec(EVAL, seed + 1), _vec(
        CONFIRM, seed + 2)
    low, high = population.single_action_space.low, population.single_action_space.high
    rng = np.random.default_rng(seed)
    ball = get_preset('american')  # start from the ball's nominal pass, spread widely
    mean = np.clip([ball.speed, ball.elevation_deg, 0.0, ball.spin_rpm, 0.0, 0.0, 0.0, 0.0],
                   low, high)
    std = 0.25 * (high - low)
    spent, curve = 0, []

    def evaluate(env, n: int) -> float:
        nonlocal spent
        _, _, _, _, info = env.step(np.tile(mean, (n, 1)))
        spent += n
        hits = float(np.mean(info['miss'] <= RADIUS))
        curve.append((spent, hits, float(np.median(info['miss']))))
        print(f'{spent:7d} throws: {100 * hits:5.1f} % of {n} within {RADIUS:g} m, median miss '
              f'{curve[-1][2]:.2f} m')
        return hits

    while spent + POPULATION + EVAL + CONFIRM <= budget:
        actions = np.clip(mean + std * rng.standard_normal((POPULATION, low.size)), low, high)
        _, reward, *_ = population.step(actions)
        spent += POPULATION
        elite = actions[np.argsort(-reward, kind='stable')[:ELITE]]
        mean = (1.0 - SMOOTHING) * mean + SMOOTHING * elite.mean(axis=0)
        std = (1.0 - SMOOTHING) * std + SMOOTHING * elite.std(axis=0) + 1e-4 * (high - low)
        if evaluate(evaluation, EVAL) >= GOAL and evaluate(confirmation, CONFIRM) >= GOAL:
            break
    return mean, curve


def plot(curve: list[tuple[int, float, float]], path: Path) -> None:
    """Draw the learning curve (fraction within 1 m and median miss against throws)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    throws, hits, miss = (np.array(c) for c in zip(*curve))
    fig, left = plt.subplots(figsize=(7, 4))
    left.plot(throws, 100 * hits, 'o-', ms=3, color='tab:blue')
    left.axhline(100 * GOAL, color='tab:blue', ls=':', lw=1)
    left.set_xlabel('throws spent (population, evaluations, confirmation)')
    left.set_ylabel("% of the mean release's throws within 1 m", color='tab:blue')
    left.set_ylim(0, 100)
    right = left.twinx()
    right.semilogy(throws, miss, 's--', ms=3, color='tab:red')
    right.set_ylabel('median miss [m]', color='tab:red')
    left.set_title('Cross-entropy method on football_ros/Throw-v0 (full model, noise 0.1)')
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--budget', type=int, default=100_000, help='most throws spent')
    parser.add_argument('--figure', type=Path, default=Path(__file__).with_suffix('.png'))
    args = parser.parse_args(argv)
    release, curve = cross_entropy(args.seed, args.budget)
    keys = football_ros.envs.ACTION_KEYS
    print('learned release: ' + ', '.join(f'{k} {v:.3f}' for k, v in zip(keys, release)))
    plot(curve, args.figure)
    print(f'figure: {args.figure}')
    return 0 if curve and curve[-1][1] >= GOAL else 1


if __name__ == '__main__':
    raise SystemExit(main(sys.argv[1:]))
