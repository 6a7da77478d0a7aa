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

"""A Release's own (plain-float) state against the vectorised path, and its limits' checks."""

import math

from football_ros.physics import frames
from football_ros.physics.release import (
    attitude_with_axis_scalar,
    initial_state_of,
    InitialState,
    LIMITS,
    Release,
    release_states,
    ReleaseError,
    STATE_KEYS,
)
from hypothesis import given, settings
from hypothesis import strategies as hs
import numpy as np
import pytest

FIELDS = ('position', 'velocity', 'axis', 'transverse_rate', 'spin', 'attitude')


def random_release(rng, ball, model):
    """Return a random valid Release (rates sometimes zero, sometimes near their limits)."""
    while True:
        kw = {k: float(rng.uniform(*LIMITS[k])) for k in STATE_KEYS}
        for k in ('alpha_rate_deg_s', 'beta_rate_deg_s'):
            kw[k] *= float(rng.choice([0.0, 0.01, 0.5]))
        kw['position'] = (float(rng.uniform(-50, 50)), float(rng.uniform(-50, 50)),
                          float(rng.uniform(0.0, 3.0)))
        try:
            return Release(ball=ball, model=model, **kw)
        except ReleaseError:
            continue  # a combined limit (total offset, transverse rate): draw again


@pytest.mark.parametrize('ball', ['american', 'rugby'])
@pytest.mark.parametrize('model', ['paper', 'full'])
def test_initial_state_is_the_vectorised_one_bit_for_bit(ball, model):
    # Exact equality (==), not a tolerance: the scalar path repeats the vectorised operations
    # in their order.
    rng = np.random.default_rng(hash((ball, model)) % 2**32)
    releases = [random_release(rng, ball, model) for _ in range(150)]
    cols = [np.array([getattr(r, k) for r in releases]) for k in STATE_KEYS]
    states = release_states(*cols, np.array([r.position for r in releases]))
    for i, release in enumerate(releases):
        mine, ref = release.initial_state(), initial_state_of(states, i)
        for name in FIELDS:
            assert np.array_equal(getattr(mine, name), getattr(ref, name)), (name, release)
        assert mine.attitude.tolist() == frames.attitude_with_axis(ref.axis).tolist()


def test_scalar_attitude_is_the_frames_one_bit_for_bit():
    # Every branch: near-vertical axes (+x of field stands in for up), the four quaternion
    # branches (axes all around), unnormalised input.
    rng = np.random.default_rng(5)
    axes = list(rng.normal(size=(400, 3)) * rng.uniform(0.1, 10.0, (400, 1)))
    axes += [np.array([1e-4, -2e-4, 1.0]), np.array([0.0, 0.0, -3.0]), np.array([-1.0, 0, 0]),
             np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 1e-3])]
    for axis in axes:
        assert list(attitude_with_axis_scalar(tuple(axis.tolist()))) == \
            frames.attitude_with_axis(axis).tolist(), axis


def test_initial_state_returns_fresh_arrays():
    release = Release(alpha0_deg=2.0, beta_rate_deg_s=30.0)
    first = release.initial_state()
    first.velocity[0] = 1e9
    first.axis[:] = 0.0
    second = release.initial_state()
    assert second.velocity[0] == pytest.approx(27.4 * math.cos(math.radians(30.0)), rel=0.2)
    assert np.linalg.norm(second.axis) == pytest.approx(1.0, abs=1e-15)


def test_release_state_satisfies_the_rigid_body_rules():
    # The state a Release keeps passes from_rigid_body, which returns it (to round-off).
    rng = np.random.default_rng(7)
    for _ in range(100):
        st = random_release(rng, 'american', 'paper').initial_state()
        back = InitialState.from_rigid_body(st.position, st.velocity, st.attitude,
                                            st.angular_velocity())
        np.testing.assert_allclose(back.axis, st.axis, atol=1e-14)
        np.testing.assert_allclose(back.transverse_rate, st.transverse_rate, atol=1e-12)
        assert back.spin == pytest.approx(st.spin, rel=1e-14)


angles = hs.floats(-70.0, 70.0, allow_nan=False)
rates = hs.floats(-5000.0, 5000.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(angles, angles, rates, rates)
def test_combined_limits_decided_as_the_rigid_body_rules(alpha, beta, alpha_rate, beta_rate):
    # A Release is refused by its combined limits exactly when from_rigid_body refuses its
    # state (the state of the vectorised path), with the same message.
    single = {'alpha0_deg': alpha, 'beta0_deg': beta, 'alpha_rate_deg_s': alpha_rate,
              'beta_rate_deg_s': beta_rate}
    if any(not LIMITS[k][0] <= v <= LIMITS[k][1] for k, v in single.items()):
        with pytest.raises(ReleaseError, match='is outside the accepted range'):
            Release(**single)
        return
    base = Release()
    kw = {k: getattr(base, k) for k in STATE_KEYS} | single
    st = initial_state_of(release_states(*(kw[k] for k in STATE_KEYS), np.zeros(3)))
    try:
        InitialState.from_rigid_body(st.position, st.velocity, st.attitude,
                                     st.angular_velocity())
        expected = None
    except ReleaseError as exc:
        expected = str(exc)
    try:
        Release(**single)
        got = None
    except ReleaseError as exc:
        got = str(exc)
    assert got == expected
