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

"""The camera model against OpenCV, its Jacobians, the ball's outline, rigs and detections."""

import math
from pathlib import Path

from football_ros.estimation.camera import ball_image, Camera
from football_ros.estimation.detections import CameraSimulator, sampled_flight, simulate
from football_ros.estimation.rig import load_rig, parse_rig
from football_ros.physics import Flight, Release
from football_ros.physics.presets import get_preset
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

cv2 = pytest.importorskip('cv2')
CONFIG = Path(__file__).resolve().parents[1] / 'config'
K = np.array([[1400.0, 0.0, 960.0], [0.0, 1390.0, 540.0], [0.0, 0.0, 1.0]])
LENSES = {
    'plumb_bob': [-0.25, 0.08, 0.001, -0.0005, -0.01],
    'rational_polynomial': [0.3, -0.1, 0.001, -0.002, 0.02, 0.5, -0.05, 0.01],
}
CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-16)


def _points(camera, n=300, seed=1):
    p = np.random.default_rng(seed).uniform([-4.0, -3.0, 3.0], [4.0, 3.0, 40.0], (n, 3))
    return p[camera.in_view(p)]


def _opencv_undistort(pixels, camera):
    src = pixels.reshape(-1, 1, 2)
    if hasattr(cv2, 'undistortPointsIter'):  # OpenCV 4
        out = cv2.undistortPointsIter(src, camera.K, camera.D, camera.R, camera.P, CRITERIA)
    else:  # OpenCV 5: undistortPoints takes the criteria
        out = cv2.undistortPoints(src, camera.K, camera.D, None, camera.R, camera.P, CRITERIA)
    return out[:, 0]


@pytest.mark.parametrize('model', sorted(LENSES))
def test_projection_and_unprojection_equal_opencv(model):
    rotation = cv2.Rodrigues(np.array([0.01, -0.02, 0.005]))[0]
    p_rect = np.column_stack([K * 1.01, [-100.0, 0.0, 0.0]])
    p_rect[2, 2] = 1.0
    camera = Camera(1920, 1080, K, np.array(LENSES[model]), model, rotation, p_rect)
    points = _points(camera)
    assert len(points) > 200
    pixels, _ = camera.project_camera(points)
    ref = cv2.projectPoints(points.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, camera.D)[0]
    assert np.abs(pixels - ref[:, 0]).max() < 1e-9
    assert np.abs(camera.rectify(pixels) - _opencv_undistort(pixels, camera)).max() < 1e-6
    rays = camera.unproject(pixels)
    assert np.abs(rays - points / points[:, 2:]).max() < 1e-12


def test_pose_moves_points_into_the_optical_frame():
    rotation = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # looking +x
    camera = Camera(1920, 1080, K, rotation=rotation, position=(1.0, 2.0, 3.0))
    px, jac = camera.project(np.array([11.0, 2.0, 3.0]))
    assert np.allclose(px, [960.0, 540.0])
    # 1 m to the left (+y) at 10 m is 140 px to the left (-u); 1 m up is 139 px up (-v).
    assert np.allclose(jac, [[0.0, -140.0, 0.0], [0.0, 0.0, -139.0]])


@pytest.mark.parametrize('model', sorted(LENSES))
def test_jacobians_match_finite_differences(model):
    rotation = cv2.Rodrigues(np.array([0.3, -1.2, 0.4]))[0]
    camera = Camera(1920, 1080, K, LENSES[model], model, rotation=rotation, position=(2, -1, 1))
    points = camera.position + _points(Camera(1920, 1080, K, LENSES[model], model)) @ rotation.T
    _, jac = camera.project(points)
    h = 1e-6
    fd = np.stack(
        [(camera.project(points + h * e)[0] - camera.project(points - h * e)[0]) / (2 * h)
         for e in np.eye(3)], axis=-1,
    )
    assert np.abs(jac - fd).max() < 1e-6 * np.abs(jac).max()


def test_outline_of_the_ball_is_the_hull_of_its_surface():
    """Without a lens the outline is exact: its box is the extent of the surface's pixels."""
    ball = get_preset('american')
    camera = Camera(1920, 1080, K)
    rng = np.random.default_rng(3)
    u = rng.normal(size=(200_000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    for centre, axis in (((0.5, -0.3, 6.0), (1.0, 0.2, 0.3)), ((-1.0, 0.4, 12.0), (0, 1, 0))):
        axis = np.array(axis, float) / np.linalg.norm(axis)
        image = ball_image(camera, np.array(centre), axis, ball.length, ball.diameter)
        # surface points: x = c + a (u.axis) axis + b (u - (u.axis) axis)
        along = u @ axis
        surface = (np.array(centre) + 0.5 * ball.length * along[:, None] * axis
                   + 0.5 * ball.diameter * (u - along[:, None] * axis))
        px = camera.project(surface)[0]
        hull = np.concatenate([px.min(axis=0), px.max(axis=0)])
        assert np.abs(image.box - hull).max() < 0.05
        assert np.allclose(image.center, camera.project(np.array(centre))[0])
        # the short axis is close to f D / depth; the long one between it and f L / depth
        assert image.width == pytest.approx(1395.0 * ball.diameter / centre[2], rel=0.03)
        assert image.width <= image.length <= 1400.0 * ball.length / centre[2] * 1.02


def test_long_axis_angle_follows_the_ball():
    camera = Camera(1920, 1080, np.array([[1400.0, 0, 960], [0, 1400.0, 540], [0, 0, 1]]))
    for deg in (-80.0, -30.0, 0.0, 45.0, 89.0):
        axis = np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg)), 0.0])
        image = ball_image(camera, np.array([0.0, 0.0, 10.0]), axis, 0.28, 0.17)
        assert image.angle == pytest.approx(math.radians(deg), abs=1e-9)
        assert image.length == pytest.approx(1400.0 * 0.28 / 10.0, rel=1e-3)


def test_points_behind_or_beyond_the_lens_fold_are_not_seen():
    camera = Camera(1920, 1080, K, [-0.4, 0.05, 0, 0, 0])  # folds back at r^2 = 1.07
    assert not camera.in_view(np.array([0.0, 0.0, -5.0]))
    assert np.all(np.isnan(camera.project(np.array([0.0, 0.0, -5.0]))[0]))
    assert ball_image(camera, np.array([0.0, 0.0, 0.1]), np.array([1.0, 0, 0]), 0.28, 0.17) is None
    # r = 2 lies beyond the fold, where the polynomial maps it back inside the image
    far = np.array([2.0, 0.0, 1.0])
    assert 0 <= camera.project(far)[0][0] < 1920 and not camera.in_view(far)
    assert camera.in_view(np.array([0.3, 0.2, 1.0]))


def test_bad_camera_info_is_refused_naming_the_field():
    cases = [
        ({'width': 0}, 'width'),
        ({'K': [1, 2, 3]}, "'K'"),
        ({'K': np.diag([-1.0, 1.0, 1.0])}, "'K'"),
        ({'D': [0.1, 0.2]}, "'D'"),
        ({'D': [np.nan] * 5}, "'D'"),
        ({'distortion_model': 'equidistant'}, 'distortion_model'),
        ({'R': np.diag([1.0, 1.0, -1.0])}, "'R'"),
        ({'P': np.zeros((3, 4))}, "'P'"),
        ({'position': (0, 0, math.inf)}, 'position'),
    ]
    for change, name in cases:
        args = {'width': 1920, 'height': 1080, 'K': K} | change
        with pytest.raises(ValueError, match=name):
            Camera(**args)


RIG = """
cameras:
  a:
    width: 640
    height: 480
    K: [500, 0, 320, 0, 500, 240, 0, 0, 1]
    position: [0, 10, 2]
    look_at: [0, 0, 2]
    rate: 50
"""


def test_rig_files_read_and_bad_fields_are_named():
    for name in ('sideline', 'stereo', 'mono'):
        rig = load_rig(CONFIG / f'rig_{name}.yaml')
        assert len(rig) == (1 if name == 'mono' else 2)
    (a,) = parse_rig(RIG)
    assert a.frame_id == 'a_optical' and a.rate == 50.0 and a.pixel_noise == 1.0
    # looking along -y from y = 10: the optical axis is -y, image right is -x, down is -z
    assert np.allclose(a.camera.rotation, [[-1, 0, 0], [0, 0, -1], [0, -1, 0]])
    bad = [
        ('rate: 50', 'rate: -1', "'a' field 'rate'"),
        ('rate: 50', 'rate: 50\n    pixel_noise: .nan', "'pixel_noise'"),
        ('K: [500, 0, 320, 0, 500, 240, 0, 0, 1]', 'K: [500, 0, 320]', "'a' field 'K'"),
        ('look_at: [0, 0, 2]', 'orientation: [0, 0, 0, 1]\n    look_at: [0, 0, 2]', 'exactly one'),
        ('look_at: [0, 0, 2]', 'look_at: [0, 10, 2]', "camera 'a': look_at"),
        ('width: 640', 'width: 640\n    zoom: 2', "unknown field 'zoom'"),
        ('  a:', '  1a:', 'camera name'),
        ('    width: 640\n', '', "'width' is missing"),
    ]
    for old, new, message in bad:
        with pytest.raises(ValueError, match=message):
            parse_rig(RIG.replace(old, new), 'x.yaml')
    with pytest.raises(ValueError, match='rig.yaml: cannot read'):
        load_rig('/nonexistent/rig.yaml')


SIDE = RIG.replace('[0, 10, 2]', '[20, 40, 5]').replace('[0, 0, 2]', '[20, 0, 5]')


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=400))
def test_any_rig_text_is_read_or_refused_with_a_value_error(text):
    try:
        parse_rig(text)
    except ValueError:
        pass


def _flight():
    ball = get_preset('american')
    release = Release(speed=22, elevation_deg=35, spin_rpm=600, position=(0, 0, 1.8), model='full')
    truth = Flight.from_release(release).simulate(rate=500.0, duration=20.0)
    return ball, truth, sampled_flight(truth.times, truth.positions, truth.velocities, truth.axes)


def test_detections_follow_the_ball_with_the_rig_s_noise_and_timing():
    ball, truth, balls_at = _flight()
    text = SIDE.replace('rate: 50', 'rate: 60\n    phase: 0.004\n    latency: 0.03\n'
                        '    pixel_noise: 0.5\n    dropout: 0.1\n    seed: 4')
    (spec,) = parse_rig(text)
    frames = simulate((spec,), balls_at, 0.0, truth.times[-1], ball.length, ball.diameter)
    stamps = np.array([f.stamp for f in frames])
    assert np.allclose(np.diff(stamps), 1 / 60) and stamps[0] == pytest.approx(0.004)
    assert all(f.delivery == pytest.approx(f.stamp + 0.03) for f in frames)
    errors, seen = [], 0
    for f in frames:
        centre, axis = balls_at(f.exposure)
        visible = bool(spec.camera.in_view(centre)[0])
        seen += visible
        for d in f.detections:
            errors.append(d.center - spec.camera.project(centre[0])[0])
    errors = np.array(errors)
    assert 0.8 * seen < len(errors) < 0.97 * seen  # 10 % dropped
    assert np.std(errors) == pytest.approx(0.5, rel=0.15) and abs(np.mean(errors)) < 0.1


def test_the_online_camera_delivers_what_the_offline_one_does():
    ball, truth, balls_at = _flight()
    (spec,) = parse_rig(SIDE)
    offline = simulate((spec,), balls_at, 0.0, 2.0, ball.length, ball.diameter)
    sim = CameraSimulator(spec, ball.length, ball.diameter)
    sim.start(0.0)
    online = []
    for now in np.arange(0.0, 2.5, 0.001):
        online += sim.step(now, balls_at)
    online = [f for f in online if f.exposure <= 2.0]
    assert [f.stamp for f in online] == [f.stamp for f in offline]
    assert all(
        np.array_equal(a.center, b.center)
        for x, y in zip(online, offline) for a, b in zip(x.detections, y.detections)
    )


def test_range_fix_covers_the_ball_as_its_covariance_says():
    """Monte Carlo of the width's noise: the range fix's errors match its covariance."""
    from football_ros.estimation.camera_fusion import range_fix

    camera = Camera(1920, 1080, K, LENSES['plumb_bob'])
    ball = np.array([1.0, -0.5, 25.0])
    width = camera.image_width(ball, 0.17)
    rng = np.random.default_rng(5)
    d2 = []
    for _ in range(400):
        center = camera.project(ball)[0] + rng.normal(0.0, 1.0, 2)
        fix = range_fix(camera, center, width + rng.normal(0.0, 1.0), 1.0, 0.17)
        e = fix.z - ball
        d2.append(e @ np.linalg.solve(fix.R, e))
    # the noises' share of the covariance is exact to first order; the width model adds 3 %
    assert 1.0 < np.mean(d2) < 3.5


def test_pixel_fix_predicts_the_camera_s_pixels_and_width():
    from football_ros.estimation.camera_fusion import pixel_fix

    camera = Camera(1920, 1080, K, LENSES['rational_polynomial'],
                    'rational_polynomial')
    points = _points(camera, 20)
    fix = pixel_fix(camera, (960.0, 540.0), 12.0, 1.0, 0.17)
    out = fix.predict(points)
    assert np.allclose(out[:, :2], camera.project(points)[0])
    # the apparent diameter of a sphere on the axis is f D / Z
    on_axis = fix.predict(np.array([[0.0, 0.0, 10.0]]))[0]
    assert on_axis[2] == pytest.approx(math.sqrt(1400.0 * 1390.0) * 0.17 / 10.0, rel=1e-9)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=3, max_size=3),
    st.floats(allow_nan=True, allow_infinity=True),
)
def test_any_detection_is_taken_or_refused_with_a_reason(values, stamp):
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.camera_fusion import CameraFusion

    fusion = CameraFusion(FlightTracker(), 1.0, 0.17)
    camera = Camera(1920, 1080, K)
    track_id, result = None, None
    answer = fusion.observe(stamp, camera, values[:2], values[2])
    if isinstance(answer, tuple):
        track_id, result = answer
        assert track_id is None and isinstance(result, str)
    else:
        assert answer.status in ('candidate', 'invalid'), answer
    assert sum(fusion.counts.values()) >= 1


@pytest.mark.parametrize('rig_name', ['sideline'])
def test_the_tracker_fuses_a_rig_s_pixels_to_the_landing(rig_name):
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.camera_fusion import CameraFusion

    rig = load_rig(CONFIG / f'rig_{rig_name}.yaml')
    ball, truth, balls_at = _flight()
    frames = simulate(rig, balls_at, 0.0, truth.times[-1], ball.length, ball.diameter)
    cams = {c.name: c.camera for c in rig}
    fusion = CameraFusion(FlightTracker(), 1.0, ball.diameter)
    t_eval = truth.times[-1] - 0.5
    for f in frames:
        if f.delivery > t_eval:
            break
        for d in f.detections:
            fusion.observe(f.stamp, cams[f.camera], d.center, d.width)
    pred = fusion.tracker.predict_landing()
    err = pred.position[:2] - truth.positions[-1, :2]
    assert np.linalg.norm(err) < 0.3
    assert err @ np.linalg.solve(pred.covariance, err) < 13.8  # inside the 99.9 % ellipse
    assert fusion.tracker.counts['accepted'] > 0.9 * fusion.counts['pixels']


def test_the_width_model_follows_a_spheroid_s_outline_off_the_optical_axis():
    """The apparent width off the axis is D sqrt(s_min s_max), within its spread of the outline."""
    rig = load_rig(CONFIG / 'rig_mono.yaml')
    camera = rig[0].camera
    ball, truth, balls_at = _flight()
    ratios, spreads = [], []
    for t in np.arange(0.2, truth.times[-1], 0.1):
        centre, axis = balls_at(t)
        image = ball_image(camera, centre[0], axis[0], ball.length, ball.diameter)
        if image is None:
            continue
        ratios.append(image.width / camera.image_width(centre, ball.diameter)[0])
        spreads.append(camera.width_spread(centre)[0])
    ratios, spreads = np.array(ratios), np.array(spreads)
    assert len(ratios) > 15
    assert np.all(np.abs(ratios - 1.0) <= spreads + 0.01)  # f D / Z alone was 1-9 % short
    assert spreads.max() > 0.03  # the image's edges stretch the outline radially
    on_axis = camera.position + camera.rotation @ np.array([0.0, 0.0, 30.0])
    assert camera.width_spread(on_axis) < 1e-6
    assert camera.image_width(on_axis, 0.17) == pytest.approx(camera.K[0, 0] * 0.17 / 30.0)


def test_the_stamps_jitter_is_measured_per_camera():
    """Two unsynchronised cameras' interleaved stamps are not read as jitter."""
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.measurement import PositionFix
    from football_ros.estimation.tracker import measured_jitter

    _, truth, balls_at = _flight()
    rng = np.random.default_rng(3)
    fixes = []
    for source, phase in (('near', 0.0), ('far', 0.0071)):
        for t in np.arange(phase + 0.05, 1.5, 1.0 / 60.0):
            fixes.append((t + rng.normal(0.0, 1e-4), balls_at(t)[0][0], source))
    fixes.sort(key=lambda f: f[0])
    tracker = FlightTracker()
    for stamp, position, source in fixes:
        z = position + rng.normal(0.0, 0.02, 3)
        tracker.observe(stamp, PositionFix(z, 4e-4 * np.eye(3), source))
    tr = tracker.track
    assert tr is not None and len(tr.fixes) > 0.9 * len(fixes)
    assert measured_jitter(list(tr.fixes)[-40:]) > 4e-4  # both cameras' stamps as one
    for source in ('near', 'far'):
        assert tracker._jitter(tr, tr.t, source) < 2.5e-4  # each camera's own: 0.1 ms


def _fed_mono(tracker):
    """Feed ``tracker`` the one-camera rig's detections of :func:`_flight` until 1 s lead."""
    from football_ros.estimation.camera_fusion import CameraFusion

    rig = load_rig(CONFIG / 'rig_mono.yaml')
    ball, truth, balls_at = _flight()
    frames = simulate(rig, balls_at, 0.0, truth.times[-1], ball.length, ball.diameter)
    cams = {c.name: c.camera for c in rig}
    fusion = CameraFusion(tracker, 1.0, ball.diameter)
    for f in frames:
        if f.delivery > truth.times[-1] - 1.0:
            break
        for d in f.detections:
            fusion.observe(f.stamp, cams[f.camera], d.center, d.width)
    return tracker


def test_a_mono_camera_s_hands_are_fitted_each_while_both_are_alive():
    """hand_fits 'pixels': a fit per hand, weighted by evidence; 'never': the filters'."""
    from football_ros.estimation import FlightTracker, TrackerSettings

    got = {}
    for mode in ('pixels', 'never'):
        tracker = _fed_mono(FlightTracker(TrackerSettings(hand_fits=mode)))
        assert tracker.hand is None  # the depth axis hides the drift that tells the hands
        got[mode] = (tracker._fits(), tracker.predict_landing())
    fits, pred = got['pixels']
    assert fits is not None and sum(w for w, _ in fits) == pytest.approx(1.0)
    assert all(math.isfinite(f.logdet) and f.cost > 0.0 for _, f in fits)
    assert got['never'][0] is None and got['never'][1] is not None
    assert np.all(np.isfinite(pred.position)) and np.all(np.linalg.eigvalsh(pred.covariance) > 0)
    with pytest.raises(ValueError, match='hand_fits'):
        TrackerSettings(hand_fits='sometimes')


def test_a_hand_s_fit_held_in_the_other_hand_s_minimum_is_fitted_again():
    """A fit warm-started from the other hand's minimum is refitted to its own (h.s its sign)."""
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.motion import X_H, X_S

    tracker = _fed_mono(FlightTracker())  # a right-handed spiral: h.s > 0
    tr = tracker.track
    assert tracker.hand is None and tracker._fits() is not None
    right, left = tr.fits[1.0][1], tr.fits[-1.0][1]
    assert right.converged and left.converged
    assert right.x0[X_H:X_H + 3] @ right.x0[X_S:X_S + 3] > 0.0
    # The trap: the right hand warm-started from the left hand's minimum (its prior alone
    # pulls the spin over; the drift's fit holds it), on the same fixes as a new key.
    tr.fits[1.0] = ((math.nan, 0), left)
    again = tracker._hand_fit(tr, 1.0)
    assert again.x0[X_H:X_H + 3] @ again.x0[X_S:X_S + 3] > 0.0
    assert again.cost <= right.cost + 1.0  # back in its own minimum, not the left's + prior
    assert again.cost < left.cost + 0.5 * ((2.0 * tracker.nominal_h1) / (
        tracker.nominal_h1 * tracker.settings.spin_sigma)) ** 2


def test_the_fit_says_whether_it_converged():
    from football_ros.estimation import FlightTracker, TrackerSettings
    from football_ros.estimation.motion import fly_state, X_H, X_KD, X_KL, X_S
    from football_ros.estimation.refine import Prior, refine

    tracker = FlightTracker(TrackerSettings())
    _, truth, _ = _flight()
    x = np.zeros(14)
    x[0:3], x[3:6] = truth.positions[0], truth.velocities[0]
    x[X_S:X_S + 3] = x[3:6] / np.linalg.norm(x[3:6])
    x[X_H:X_H + 3] = tracker.nominal_h1 * x[X_S:X_S + 3]
    x[X_KD] = x[X_KL] = 1.0
    times = np.arange(0, 60) / 60.0
    zs = fly_state(x, times, tracker.params, 0.005)[1]
    prior = Prior((tracker.nominal_h1, 0.19 * tracker.nominal_h1), 0.03, 0.3,
                  ((X_KD, 1.0, 0.2), (X_KL, 1.0, 0.2)))
    start = x.copy()
    start[3:6] += (1.0, -1.0, 0.5)
    short = refine(times, zs, start, prior, 0.02, tracker.params, 0.005, 1)
    full = refine(times, zs, start, prior, 0.02, tracker.params, 0.005, 25)
    assert not short.converged and short.cost > 1.0  # one step from 1 m/s off: far from it
    assert full.converged and full.cost < 1e-6 and full.iterations < 25


def test_a_mono_throw_is_judged_at_its_own_release_speed_not_the_start_arc_s():
    """
    One camera: S_g (the tumbling allowance) is judged at the filters' release speed.

    The start arc's speed along the ray was 147 m/s for this 22 m/s spiral, S_g judged there
    called it a tumbling kick, and the prediction took the filters' covariance (sigmas 1.0
    and 3.8 m, NEES 0.005: 0.27 m off); the filters' spin, unknown in one view, no longer
    decides either.
    """
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.motion import X_H
    from football_ros.estimation.tracker import _spin_known

    ball, truth, _ = _flight()
    tracker = _fed_mono(FlightTracker())
    assert tracker.track.release_speed == pytest.approx(22.0, abs=1.5)
    vague = tracker.track.best.copy()
    assert _spin_known(vague)
    vague.P[X_H:X_H + 3, X_H:X_H + 3] = 50.0**2 * np.eye(3)  # as one camera's start left it
    assert not _spin_known(vague)
    assert tracker._stability(tracker._fits()[0][1].x) > 2.0  # a spiral
    pred = tracker.predict_landing()
    err = pred.position[:2] - truth.positions[-1, :2]
    assert np.sqrt(np.linalg.eigvalsh(pred.covariance)).max() < 0.8  # was 3.8 m
    assert np.linalg.norm(err) < 0.5 and err @ np.linalg.solve(pred.covariance, err) < 5.991


def test_a_throw_that_lost_the_ball_starts_again_from_the_camera_s_range_fixes():
    """
    A track whose start was wrong rejects the pixels in a row; their range fixes restart it.

    The start: fixes of the ball 4 m nearer the mono camera than it was (an arc off along the
    ray). Without the restart every later pixel fix was rejected (27 in a row on a mono flight
    of the benchmark) and the throw never predicted from them.
    """
    from football_ros.estimation import FlightTracker
    from football_ros.estimation.camera_fusion import CameraFusion
    from football_ros.estimation.multi import MultiTracker

    rig = load_rig(CONFIG / 'rig_mono.yaml')
    ball, truth, balls_at = _flight()
    frames = simulate(rig, balls_at, 0.0, truth.times[-1], ball.length, ball.diameter)
    cams = {c.name: c.camera for c in rig}
    t_eval = truth.times[-1] - 1.0
    for tracker in (FlightTracker(), MultiTracker()):
        fusion = CameraFusion(tracker, 1.0, ball.diameter)
        wrong = 0
        for f in frames:
            if f.delivery > t_eval:
                break
            if f.stamp < 0.1:  # the wrong start: positions of the ball moved towards the camera
                tracker.update(f.stamp, balls_at(f.exposure)[0][0] + (0.0, 4.0, 0.0))
                wrong = f.stamp
                continue
            for d in f.detections:
                fusion.observe(f.stamp, cams[f.camera], d.center, d.width)
        if isinstance(tracker, MultiTracker):
            ended = [e.reason for e in tracker.events if e.kind == 'ended']
            assert ended and 'in a row beyond the gate' in ended[0], tracker.events
            tracker = tracker.taken_by
        tr = tracker.track
        assert 'in a row beyond the gate' in tracker.restart_reason
        assert min(tr.fixes) > wrong and tr.rejected_in_row == 0  # the new throw's own fixes
        assert len(tr.fixes) > 50  # the pixels after the restart, taken
        err = tracker.predict_landing().position[:2] - truth.positions[-1, :2]
        assert err @ np.linalg.solve(tracker.predict_landing().covariance, err) < 13.8  # 99.9 %


def test_one_camera_s_gusty_twins_do_not_overrule_a_steady_fit_that_explains_the_fixes():
    """
    With pixels, the steady fit's chi-square, not the filters' odds, tells whether air gusts.

    One camera's still-air filters lose to their gusty twins in still air (over half the
    likelihood in 5 of 20 flights of the benchmark's mono rig), which dropped the fit for the
    filters' mixture, metres off along the ray. Here the twins are handed all the likelihood.
    """
    from football_ros.estimation import FlightTracker

    _, truth, _ = _flight()
    tracker = _fed_mono(FlightTracker())
    tr = tracker.track
    steady = tracker.predict_landing()
    for h in tr.hyps:
        h.loglik += 100.0 if h.gusty else 0.0
    assert tracker._gusty_weight(tr) > 0.999
    fits = tracker._fits()  # chi-square 574 for 564 degrees of freedom: it passes
    assert fits is not None and all(f.cost < 1.1 * f.dof for _, f in fits)
    pred = tracker.predict_landing()  # the gusty share held at gust_prior
    assert np.linalg.norm(pred.position[:2] - steady.position[:2]) < 0.05
    err = pred.position[:2] - truth.positions[-1, :2]
    assert np.linalg.norm(err) < 0.25 and err @ np.linalg.solve(pred.covariance, err) < 5.991
    filters = tracker._mixture(tr, -math.inf, np.zeros(4))[0][0][1:]  # measured 0.44 m off
    assert np.linalg.norm(filters - truth.positions[-1, :2]) > 0.35  # (the fit 0.17 m)
    tr.pixels = False  # positions alone: the filters' odds rule the fit out, as before
    assert tracker._fits() is None
    # The twins outweighed the still-air filters by hand_odds: these are dropped, and the fit
    # starts from a gusty filter, its wind left out (it had no start: the filters' mixture)
    tr.pixels, tr.fits = True, {}
    tr.hyps = [h for h in tr.hyps if h.gusty]
    assert tracker._fits() is not None
    err = tracker.predict_landing().position[:2] - truth.positions[-1, :2]
    assert np.linalg.norm(err) < 0.25
