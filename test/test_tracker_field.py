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

"""The tracker in the field: per-fix covariances, measurement models, slow and jittery cameras."""

import math

from football_ros.estimation import FlightTracker, TrackerSettings
from football_ros.estimation.measurement import (
    check_covariance,
    PositionFix,
    ProjectedFix,
    unscented_update,
    Whitener,
    with_timing,
)
from football_ros.estimation.multi import MultiTracker
from football_ros.estimation.tracker import measured_jitter
from football_ros.physics import Flight, Release
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

RELEASE = Release(model='full', position=(0.0, 0.0, 1.8))


def seen(release, rate=60.0, noise=0.02, seed=1, jitter=0.0, depth=None):
    """
    Return the fixes [(stamp, position, covariance)] before the landing, its time and x y.

    ``jitter`` [s] on the stamps (the position is the true one at the true time); ``depth``
    [m]: the noise along y is that instead of ``noise`` (a mono camera looking along y).
    """
    flight = Flight.from_release(release)
    truth = flight.simulate(rate=1000.0)
    t_land = float(truth.times[-1])
    rng = np.random.default_rng(seed)
    sig = np.array([noise, noise if depth is None else depth, noise])
    out = []
    for k in range(int(t_land * rate) + 1):
        t = k / rate
        z = flight.state_at(t)[:3] + rng.normal(0.0, sig)
        out.append((t + rng.normal(0.0, jitter) if jitter else t, z, np.diag(sig**2)))
    return out, t_land, truth.positions[-1, :2]


def nees(pred, xy) -> float:
    e = pred.position[:2] - xy
    return float(e @ np.linalg.solve(pred.covariance, e))


# --- the measurement models -------------------------------------------------------------------
def test_projected_fix_update_is_the_kalman_update_of_a_linear_projection():
    rng = np.random.default_rng(3)
    n = 8
    A = rng.normal(size=(n, n))
    P = A @ A.T / n + np.eye(n) * 0.1
    x = rng.normal(size=n)
    H = np.array([[1.0, 0.5, 0.0], [0.0, -0.3, 2.0]])  # two "pixels" of the position
    R = np.array([[0.04, 0.01], [0.01, 0.09]])
    z = np.array([0.3, -0.2])
    fix = ProjectedFix(z, R, project=lambda r: r @ H.T)
    up = unscented_update(x, P, fix, 0.5)
    Hx = np.zeros((2, n))
    Hx[:, :3] = H
    S = Hx @ P @ Hx.T + R
    K = P @ Hx.T @ np.linalg.inv(S)
    nu = z - Hx @ x
    np.testing.assert_allclose(up.x, x + K @ nu, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(up.P, P - K @ S @ K.T, rtol=1e-9, atol=1e-12)
    assert up.d2 == pytest.approx(float(nu @ np.linalg.solve(S, nu)), rel=1e-9)
    assert up.logdet == pytest.approx(math.log(np.linalg.det(S)), rel=1e-9)
    # The same position measured as a position: the same update as the projection by I.
    pos = PositionFix(np.array([0.1, 0.2, 0.3]), np.diag([1e-4, 4e-4, 9e-4]))
    same = ProjectedFix(pos.z, pos.R, project=lambda r: r)
    a, b = unscented_update(x, P, pos, 0.5), unscented_update(x, P, same, 0.5)
    np.testing.assert_allclose(a.x, b.x, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.P, b.P, rtol=1e-8, atol=1e-12)


def test_timing_jitter_widens_the_fix_along_the_velocity_only():
    fix = PositionFix(np.zeros(3), 1e-4 * np.eye(3))
    v = np.array([20.0, 0.0, 5.0])
    wide = with_timing(fix, np.zeros(3), v, 0.005)
    np.testing.assert_allclose(wide.R, 1e-4 * np.eye(3) + 0.005**2 * np.outer(v, v), rtol=1e-9)
    assert with_timing(fix, np.zeros(3), v, 0.0) is fix
    # Pixels of a camera along y (focal 1000 px): the jitter moves the image along v's image.
    H = np.array([[1000.0, 0.0, 0.0], [0.0, 0.0, 1000.0]]) / 30.0
    pix = ProjectedFix(np.zeros(2), np.eye(2), project=lambda r: r @ H.T)
    wide = with_timing(pix, np.zeros(3), v, 0.002)
    np.testing.assert_allclose(wide.R, np.eye(2) + 0.002**2 * np.outer(H @ v, H @ v), rtol=1e-6)


def test_whitener_is_the_cholesky_whitening_of_each_fix():
    rng = np.random.default_rng(5)
    fixes = []
    for k in range(4):
        A = rng.normal(size=(3, 3))
        fixes.append(PositionFix(rng.normal(size=3), A @ A.T + 0.01 * np.eye(3)))
    H = np.array([[2.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    fixes.append(
        ProjectedFix(np.array([0.5, 1.0]), np.diag([0.25, 1.0]), project=lambda r: r @ H.T)
    )
    white = Whitener(fixes)
    pos = rng.normal(size=(2, 5, 3))
    res = white(pos)
    assert res.shape == (2, 14) and white.size == 14
    for n in range(2):  # the squared norm is the sum of the fixes' Mahalanobis distances
        chi2 = sum(
            float((f.predict(pos[n, k][None])[0] - f.z)
                  @ np.linalg.solve(f.R, f.predict(pos[n, k][None])[0] - f.z))
            for k, f in enumerate(fixes)
        )
        assert float(res[n] @ res[n]) == pytest.approx(chi2, rel=1e-9)


@pytest.mark.parametrize(
    'cov, words',
    [
        ([[1.0, 0.0], [0.0, 1.0]], '3x3'),
        (np.full((3, 3), np.nan), 'non-finite'),
        ([[1e-4, 1e-5, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]], 'symmetric'),
        (-1e-4 * np.eye(3), 'positive definite'),
        (1e6 * np.eye(3), 'positive definite'),
        ('abc', 'numbers'),
    ],
)
def test_bad_covariances_are_refused_naming_the_field(cov, words):
    with pytest.raises(ValueError, match=words):
        check_covariance(cov, 3)
    tracker = FlightTracker()
    result = tracker.update(0.0, (0.0, 0.0, 1.0), covariance=cov)
    assert result.status == 'invalid' and result.reason.startswith('covariance') and words in (
        result.reason
    )
    track_id, result = MultiTracker().update(0.0, (0.0, 0.0, 1.0), covariance=cov)
    assert track_id is None and result.status == 'invalid' and 'covariance' in result.reason


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(-1.0, 3.0),
            st.lists(st.floats(allow_nan=True, allow_infinity=True, width=32), min_size=9,
                     max_size=9),
        ),
        max_size=12,
    )
)
def test_fuzz_covariances_never_raise(stream):
    tracker = FlightTracker()
    for k, (t, cov) in enumerate(stream):
        result = tracker.update(k / 60.0, (k * 0.3, 0.0, 2.0 + k * 0.1), covariance=cov)
        assert result.status in ('started', 'candidate', 'accepted', 'invalid', 'outlier')
        est = tracker.estimate
        if est is not None:
            assert np.all(np.isfinite(est[1])) and np.all(np.isfinite(est[2]))


# --- the tracker on the field's cameras -------------------------------------------------------
def run(fixes, tracker, t_land, lead=1.0, covariances=True):
    """Feed the fixes up to ``lead`` [s] before the landing; return the starts and prediction."""
    for t, z, cov in sorted(fixes, key=lambda f: f[0]):
        if t > t_land - lead:
            break
        tracker.update(t, z, covariance=cov if covariances else None)
    return tracker.throws, tracker.predict_landing()


def test_measured_jitter_recovers_the_stamps_jitter():
    rng = np.random.default_rng(2)
    for rate, jitter in ((60.0, 0.005), (30.0, 0.01), (120.0, 0.002)):
        stamps = np.arange(200) / rate + rng.normal(0.0, jitter, 200)
        assert measured_jitter(stamps) == pytest.approx(jitter, rel=0.25)
    regular = np.delete(np.arange(100) / 60.0, [5, 17, 40, 41, 77])  # dropped frames
    assert measured_jitter(np.concatenate([regular, regular])) < 1e-9  # and doubles


@pytest.mark.parametrize('rate', [10.0, 15.0])
def test_a_slow_camera_starts_one_throw_and_predicts_it(rate):
    fixes, t_land, xy = seen(RELEASE, rate=rate, seed=4)
    tracker = FlightTracker()
    throws, pred = run(fixes, tracker, t_land, lead=0.5)
    assert throws == 1
    assert pred is not None and nees(pred, xy) < 13.8  # 99.9 % of an honest 2-dof NEES
    assert np.linalg.norm(pred.position[:2] - xy) < 0.5


def test_an_untold_stamp_jitter_does_not_split_the_throw_and_stays_honest():
    fixes, t_land, xy = seen(RELEASE, seed=6, jitter=0.005)
    tracker = FlightTracker()
    throws, pred = run(fixes, tracker, t_land, lead=0.5)
    assert throws == 1 and tracker.counts['outlier'] <= 2
    assert nees(pred, xy) < 13.8
    told = FlightTracker(TrackerSettings(stamp_jitter=0.005))
    throws, pred = run(fixes, told, t_land, lead=0.5)
    assert throws == 1 and nees(pred, xy) < 13.8


def test_a_mono_cameras_depth_noise_told_per_fix():
    """1 cm across, 15 cm in depth (y): told per fix, the landing's y spread is the wider."""
    fixes, t_land, xy = seen(RELEASE, noise=0.01, depth=0.15, seed=8)
    tracker = FlightTracker(TrackerSettings(noise=0.01))
    throws, pred = run(fixes, tracker, t_land, lead=1.0)
    assert throws == 1 and pred is not None
    assert pred.covariance[1, 1] > 2.0 * pred.covariance[0, 0]
    assert nees(pred, xy) < 13.8


# --- frames and diagnostics ---------------------------------------------------------------------
def test_static_frames_compose_both_ways_and_refuse_bad_transforms():
    from football_ros.estimation.static_frames import StaticFrames

    frames = StaticFrames()
    s = math.sqrt(0.5)
    frames.add('field', 'mast', (10.0, 0.0, 5.0), (0.0, 0.0, s, s))  # 90 deg about z
    frames.add('mast', 'camera', (0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    R, t = frames.lookup('field', 'camera')
    # the camera 1 m along the mast's y (field -x) from (10, 0, 5); its x is field y
    np.testing.assert_allclose(R @ np.array([1.0, 0.0, 0.0]) + t, [9.0, 1.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(t, [9.0, 0.0, 5.0], atol=1e-12)
    Ri, ti = frames.lookup('camera', 'field')
    np.testing.assert_allclose(Ri @ (R @ np.array([0.3, -2.0, 4.0]) + t) + ti, [0.3, -2.0, 4.0],
                               atol=1e-12)
    assert frames.lookup('field', 'elsewhere') is None
    for args, words in (
        (('field', 'field', (0, 0, 0), (0, 0, 0, 1)), 'itself'),
        (('field', 'x', (math.nan, 0, 0), (0, 0, 0, 1)), 'translation'),
        (('field', 'x', (0, 0, 0), (0, 0, 0, 0)), 'quaternion'),
        (('', 'x', (0, 0, 0), (0, 0, 0, 1)), 'non-empty'),
    ):
        with pytest.raises(ValueError, match=words):
            frames.add(*args)
    frames.add('camera', 'mast', (0, 0, 0), (0, 0, 0, 1))  # a loop: no root, no lookup
    assert frames.lookup('field', 'camera') is None


def test_fix_of_moves_a_covariance_fix_into_the_field():
    tracker_node = pytest.importorskip('football_ros.nodes.tracker')
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from football_ros.estimation.static_frames import StaticFrames

    frames = StaticFrames()
    s = math.sqrt(0.5)
    frames.add('field', 'cam', (1.0, 2.0, 3.0), (0.0, 0.0, s, s))
    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = 'cam'
    msg.pose.pose.position.x = 4.0
    cov = np.zeros((6, 6))
    cov[:3, :3] = np.diag([1e-4, 1e-2, 4e-4])  # depth along the camera's y
    msg.pose.covariance = [float(c) for c in cov.ravel()]
    position, c = tracker_node.fix_of(msg, 'field', frames)
    np.testing.assert_allclose(position, [1.0, 6.0, 3.0], atol=1e-12)
    np.testing.assert_allclose(c, np.diag([1e-2, 1e-4, 4e-4]), atol=1e-15)  # now along -x
    msg.header.frame_id = 'nowhere'
    assert 'nowhere' in tracker_node.fix_of(msg, 'field', frames)
    msg.header.frame_id = 'field'
    msg.pose.covariance = [0.0] * 36
    assert tracker_node.fix_of(msg, 'field', frames)[1] is None  # not given


def test_fixes_that_start_no_throw_give_one_event_saying_why():
    multi = MultiTracker()
    for k in range(90):  # 1.5 s of a ball rolling slowly on the ground at 60 Hz
        multi.update(k / 60.0, (0.5 * k / 60.0, 0.0, 0.11))
    events = [e for e in multi.events if e.kind == 'no_start']
    assert len(events) == 1 and 'do not move like a throw' in events[0].reason
    assert events[0].time == pytest.approx(1.0, abs=0.02) and 'every 17 ms' in events[0].reason


def test_a_start_faster_than_a_throw_is_refused_and_one_along_a_ray_is_drawn_in():
    """
    max_speed: an arc faster than any release starts no throw, saying why.

    A start seen along a camera's ray (its speed tens of m/s uncertain) is taken under the weak
    physical prior of a throw's velocity: its speed and its covariance stay physical.
    """
    assert TrackerSettings().max_speed == 60.0  # the fastest release (physics.release.LIMITS)
    g = np.array([0.0, 0.0, -9.81])
    v0 = np.array([100.0, 30.0, 40.0])  # 111 m/s
    results, trackers = {}, {}
    for top in (60.0, 150.0):
        trackers[top] = tracker = FlightTracker(TrackerSettings(max_speed=top))
        for k in range(8):
            t = k / 120.0
            results[top] = tracker.update(t, np.array([0.0, 0.0, 1.8]) + v0 * t + 0.5 * g * t * t)
    assert results[60.0].status == 'candidate' and trackers[60.0].track is None
    assert 'faster than a throw' in results[60.0].reason and '111.' in results[60.0].reason
    assert results[150.0].used and trackers[150.0].track is not None
    with pytest.raises(ValueError, match='min_speed'):
        TrackerSettings(min_speed=10.0, max_speed=5.0)
    # The prior's pseudo-fix v = 0 of sigma max_speed / 2: a ray along y, 80 m/s of sigma
    tracker = FlightTracker()
    x0 = np.array([20.0, 5.0, 6.0, 15.0, 100.0, 8.0])
    cov = np.diag([0.01, 64.0, 0.01, 0.25, 6400.0, 0.25])
    cov[1, 4] = cov[4, 1] = 0.9 * 8.0 * 80.0  # the range and the speed along the ray
    x1, cov1 = tracker._physical(x0, cov)
    shrink = 6400.0 / (6400.0 + 900.0)
    assert x1[4] == pytest.approx(100.0 * (1.0 - shrink))  # 12.3 m/s
    assert x1[1] == pytest.approx(5.0 - 0.9 * 8.0 * 80.0 / 7300.0 * 100.0)  # moved with it
    assert cov1[4, 4] == pytest.approx(6400.0 * 900.0 / 7300.0) and cov1[4, 4] < 900.0
    assert x1[3] == pytest.approx(15.0 * 900.0 / 900.25)  # a precise axis: 0.03 %
    assert np.linalg.norm(x1[3:]) < 25.0
    # End to end: a mono camera's 8 m along y from the start
    fixes, _, _ = seen(RELEASE, rate=120.0, depth=8.0, seed=2)
    tracker = FlightTracker()
    for t, z, c in fixes[:20]:
        tracker.update(t, z, covariance=c)
    start = tracker.track.history[0].hyps[0]
    assert np.linalg.norm(start.x[3:6]) < 60.0 and start.P[4, 4] < 1.01 * 900.0
