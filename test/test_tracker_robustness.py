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

"""The tracker and the camera under hostile and busy inputs (issue 23)."""

import math

from football_ros.estimation import FlightTracker, TrackerSettings
from football_ros.estimation.motion import land_points, N_X, path_of, propagate_points
import numpy as np
import pytest

G = 9.80665


def _at_rest(z: float, axis=(1.0, 0.0, 0.0)) -> np.ndarray:
    x = np.zeros(N_X)
    x[2] = z
    x[6:9] = axis
    x[12] = x[13] = 1.0
    return x


@pytest.mark.parametrize('axis', [(1.0, 0.0, 0.0), (0.0, 0.0, 0.0)])
def test_kernels_fly_a_ball_at_rest_or_without_axis_instead_of_dividing_by_zero(axis):
    tracker = FlightTracker()
    x = _at_rest(1.0, axis)
    # Dropped from 1 m: it falls in sqrt(2 h / g) (drag adds well under a millisecond).
    land = land_points(x[None, :].copy(), tracker.params, 0.01, 0.0, 15.0)
    assert land[0, 3] == 1.0
    assert land[0, 0] == pytest.approx(math.sqrt(2.0 / G), abs=2e-3)
    assert np.allclose(land[0, 1:3], 0.0, atol=1e-3)  # a little lift, no more
    times, pos = path_of(x, tracker.params, 0.05, 0.01, 0.0, 15.0)
    assert times[-1] == pytest.approx(math.sqrt(2.0 / G), abs=2e-3)
    assert pos[-1, 2] == 0.0 and np.all(np.isfinite(pos))
    pts = x[None, :].copy()
    propagate_points(pts, 0.2, tracker.params, 0.005)
    assert pts[0, 2] == pytest.approx(1.0 - 0.5 * G * 0.04, abs=1e-3)
    assert pts[0, 5] == pytest.approx(-G * 0.2, abs=1e-2)


def test_non_finite_points_come_out_as_nan_not_as_an_exception():
    tracker = FlightTracker()
    pts = np.stack([_at_rest(1.0), _at_rest(1.0)])
    pts[1, 4] = math.nan
    propagate_points(pts, 0.1, tracker.params, 0.005)
    assert np.all(np.isfinite(pts[0])) and np.all(np.isnan(pts[1]))
    pts = np.stack([_at_rest(1.0), _at_rest(1.0)])
    pts[1, 9] = math.inf
    land = land_points(pts, tracker.params, 0.01, 0.0, 15.0)
    assert land[0, 3] == 1.0 and land[1, 3] == 0.0


def test_a_ball_held_still_is_tracked_without_an_internal_error():
    tracker = FlightTracker(TrackerSettings(min_speed=0.0))
    for k in range(40):  # the same point, exactly: zero velocity, a zero-division magnet
        result = tracker.update(k / 60.0, (1.0, 2.0, 1.5))
        assert result.status in ('candidate', 'started', 'accepted', 'outlier')
    pred = tracker.predict_landing()
    path = tracker.predict_path(0.05)
    assert tracker.track is not None
    if pred is not None:
        assert np.all(np.isfinite(pred.position)) and np.all(np.isfinite(pred.covariance))
    if path is not None:
        assert np.all(np.isfinite(path[1]))
