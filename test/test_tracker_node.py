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
Tracker node across processes.

simulator camera -> tracker -> landing prediction, and hostile fixes.
"""

import math
import re
import time

from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from geometry_msgs.msg import PointStamped, PoseStamped, PoseWithCovarianceStamped
from nav_msgs.msg import Odometry, Path
import numpy as np
import pytest
from rosutil import order_flight


def stamp_ns(msg):
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def stamp_s(msg):
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def landed_values(collector):
    """Values of every 'landed' event on /diagnostics, in order."""
    out = []
    for arr in collector.get(qos.DIAGNOSTICS):
        for st in arr.status:
            values = {kv.key: kv.value for kv in st.values}
            if values.get('event') == 'landed':
                out.append(values)
    return out


def wait_until_quiet(collector, topic, quiet=2.0, timeout=20.0):
    """
    Wait until ``topic`` has had messages and none for ``quiet`` [s] (all delivered).

    2 s: a tracker that runs behind on a loaded machine (a batch fit at every fix) can pause
    for half a second and more while it still has fixes to go (a clean-clone run took a
    prediction 0.4 m short of the landing for the last one after a 0.5 s window).
    """
    collector.wait_for(
        lambda: collector.arrivals[topic][-1:]
        and time.monotonic_ns() - collector.arrivals[topic][-1] > quiet * 1e9,
        timeout,
        f'the last message on {topic}',
    )


def subscribe_outputs(collector):
    collector.subscribe(Odometry, qos.ESTIMATE, qos.STATE)
    collector.subscribe(PoseWithCovarianceStamped, qos.LANDING, qos.STATE)
    collector.subscribe(Path, qos.PREDICTED_PATH, qos.STATE)


def assert_all_finite(collector):
    for odom in collector.get(qos.ESTIMATE):
        p, v = odom.pose.pose.position, odom.twist.twist.linear
        assert all(math.isfinite(c) for c in (p.x, p.y, p.z, v.x, v.y, v.z))
        assert np.all(np.isfinite(odom.pose.covariance))
        assert np.all(np.isfinite(odom.twist.covariance))
    for land in collector.get(qos.LANDING):
        p = land.pose.pose.position
        assert all(math.isfinite(c) for c in (p.x, p.y, p.z))
        assert np.all(np.isfinite(land.pose.covariance))
    for path in collector.get(qos.PREDICTED_PATH):
        assert all(
            math.isfinite(ps.pose.position.x) and math.isfinite(ps.pose.position.z)
            for ps in path.poses
        )


def test_prediction_converges_to_the_simulators_landing(start_node, collector):
    """
    Two throws (right- then left-handed, the second after the first landed).

    Camera at 60 Hz with 2 cm noise, 20 ms latency, 10 % dropouts and 2 % outliers.
    """
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'model:=full',
        '-p',
        'publish_rate:=200.0',
        '-p',
        'observation_rate:=60.0',
        '-p',
        'observation_noise:=0.02',
        '-p',
        'observation_latency:=0.02',
        '-p',
        'observation_dropout:=0.1',
        '-p',
        'observation_outlier_rate:=0.02',
        '-p',
        'observation_outlier_size:=3.0',
        '-p',
        'observation_seed:=7',
        '-p',
        'hold_rate:=0.0',
    )
    tracker = start_node('tracker', '--ros-args', '-p', 'prediction_rate:=1000.0')
    subscribe_outputs(collector)
    collector.subscribe(PointStamped, qos.OBSERVATION, qos.STATE)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    # The tracker must see the throws from their release: wait until discovery has matched it.
    collector.wait_for(
        lambda: (
            collector.node.count_subscribers('/' + qos.OBSERVATION) >= 2
            and collector.node.count_publishers('/' + qos.OBSERVATION) >= 1
        ),
        20.0,
        'the tracker and the camera',
    )
    time.sleep(1.0)
    for k, release in enumerate(
        [
            Release(position=(0.0, 0.0, 1.8)),
            Release(
                speed=24.0,
                elevation_deg=35.0,
                spin_rpm=-650.0,
                azimuth_deg=10.0,
                position=(5.0, 2.0, 1.8),
            ),
        ]
    ):
        collector.clear()
        order_flight(collector, release, f'track-{k}')
        collector.wait_for(lambda: len(landed_values(collector)) >= 1, 15.0, 'the landing')
        # The tracker may run behind the simulator on a loaded machine (it predicts on every
        # fix here): wait until its predictions of this throw have stopped.
        wait_until_quiet(collector, qos.LANDING)
        landed = landed_values(collector)[0]
        x_land, y_land = float(landed['landing_x']), float(landed['landing_y'])
        t_flight = float(landed['time_of_flight'])
        # The simulator's landing is the full model's (independent check of the event).
        expected = Flight.from_release(release.replace(model='full')).simulate(rate=200.0)
        x_exp, y_exp = expected.positions[-1, :2]
        assert math.hypot(x_land - x_exp, y_land - y_exp) < 1e-6
        release_stamp = stamp_s(collector.get(qos.POSE)[0])
        obs = collector.get(qos.OBSERVATION)
        assert 0.75 * 60 * t_flight < len(obs) < 60 * t_flight + 2  # 10 % dropped
        # Observation stamps are capture times: k / 60 s after the release (up to 1 ns).
        release_ns = stamp_ns(collector.get(qos.POSE)[0])
        offsets = [stamp_ns(o) - release_ns for o in obs]
        assert max(abs(d - round(d * 60 / 1e9) * 1e9 / 60) for d in offsets) < 1000
        landings = collector.get(qos.LANDING)
        assert len(landings) > 20, tracker.log()
        # Which estimate each prediction was made from: the last one that arrived before it
        # (the node publishes the estimate, then the prediction, for each fix).
        n_est = len(collector.get(qos.ESTIMATE))
        est_arrivals = np.array(collector.arrivals[qos.ESTIMATE][:n_est])
        est_stamps = np.array([stamp_s(m) for m in collector.get(qos.ESTIMATE)])
        made_at = [
            est_stamps[np.searchsorted(est_arrivals, a) - 1] - release_stamp
            for a in collector.arrivals[qos.LANDING][: len(landings)]
        ]
        t_land = release_stamp + t_flight

        def error(m):
            p = m.pose.pose.position
            return math.hypot(p.x - x_land, p.y - y_land)

        lead_1s = [m for m, t in zip(landings, made_at) if t <= t_flight - 1.0]
        assert lead_1s, (k, t_flight, made_at[:5], len(est_stamps), tracker.log()[-3000:])
        assert error(lead_1s[-1]) < 0.5, [error(m) for m in lead_1s[-5:]]
        final = landings[-1]
        assert error(final) < 0.1 and final.pose.pose.position.z == 0.0
        assert abs(stamp_s(final) - t_land) < 0.02  # header.stamp = the predicted landing time
        sigma = math.sqrt(final.pose.covariance[0] + final.pose.covariance[7])
        assert 0.0 < sigma < 0.3
        path = collector.get(qos.PREDICTED_PATH)[-1]
        assert path.poses and path.poses[-1].pose.position.z == 0.0
        assert_all_finite(collector)
    log = tracker.log()
    # Each throw seen to its end although the camera lost its last frame before the ground.
    assert log.count('new throw') == 2 and log.count('ended: landed') == 2, log
    assert log.count('landed: predicted landing') == 2, log
    assert 'Traceback' not in log


def point(stamp_s_, xyz, frame='field'):
    msg = PointStamped()
    msg.header.frame_id = frame
    sec = int(math.floor(stamp_s_))
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, int((stamp_s_ - sec) * 1e9)
    msg.point.x, msg.point.y, msg.point.z = (float(v) for v in xyz)
    return msg


def test_hostile_fixes_never_crash_or_poison_the_tracker(start_node, collector):
    tracker = start_node('tracker')
    subscribe_outputs(collector)
    pub = collector.publisher(PointStamped, qos.OBSERVATION, qos.STATE)
    collector.wait_for_subscribers(pub)
    release = Release(model='full', position=(0.0, 0.0, 1.8))
    truth = Flight.from_release(release).simulate(rate=60.0)
    rng = np.random.default_rng(3)
    base = time.time() - 5.0  # a throw captured in the recent past (not "from the future")
    nan, inf = float('nan'), float('inf')
    sent = 0
    for k, (t, p) in enumerate(zip(truth.times[:-1], truth.positions[:-1])):
        fix = p + rng.normal(0.0, 0.02, 3)
        pub.publish(point(base + t, fix))
        sent += 1
        if k % 7 == 3:  # hostile fixes between the good ones
            for bad in (
                point(base + t + 0.001, (nan, 0.0, 1.0)),
                point(base + t + 0.002, (1.0, inf, 1.0)),
                point(base + t + 0.003, (1e30, -1e30, 1e30)),
                point(base + t + 0.004, p + np.array([40.0, -30.0, 20.0])),
                point(1.0, p),  # far in the past
                point(base + 1e6, p),  # far in the future
                point(base + t + 0.005, p, 'camera'),  # wrong frame
                point(base + t, fix),
            ):  # duplicate stamp
                pub.publish(bad)
        if k % 11 == 5 and k > 20:  # a late but valid fix, 25 ms older than the newest
            pub.publish(point(base + t - 0.025, truth.positions[k - 1] + rng.normal(0.0, 0.02, 3)))
        if k % 20 == 0:
            time.sleep(0.01)
    wait_until_quiet(collector, qos.LANDING, timeout=30.0)  # the node may lag
    assert len(collector.get(qos.LANDING)) > 5, tracker.log()
    assert tracker.proc.poll() is None, tracker.log()
    assert 'Traceback' not in tracker.log() and 'internal error' not in tracker.log()
    assert 'fix refused' in tracker.log()
    assert_all_finite(collector)
    final = collector.get(qos.LANDING)[-1].pose.pose.position
    x_land, y_land = truth.positions[-1, :2]
    assert math.hypot(final.x - x_land, final.y - y_land) < 0.15
    assert tracker.log().count('new throw') == 1  # the outliers never started a throw


def test_prediction_throttle_runs_on_the_fixes_clock():
    from football_ros.nodes.tracker import PredictionThrottle

    throttle = PredictionThrottle(30.0)
    stamps = 1e6 + np.arange(120) / 60.0  # 2 s of 60 Hz fixes, whatever the node clock says
    assert sum(throttle.due(t) for t in stamps) == 60
    # Fixes stamped on a clock that started again: predictions at once, then every 1 / 30 s.
    again = np.arange(30) / 60.0
    assert [throttle.due(t) for t in again[:3]] == [True, False, True]


def _clock(seconds):
    from rosgraph_msgs.msg import Clock

    msg = Clock()
    msg.clock.sec = int(seconds)
    msg.clock.nanosec = int(round((seconds - int(seconds)) * 1e9))
    return msg


def test_a_strangers_clock_and_a_clock_restart_under_sim_time(start_node, collector):
    from rosgraph_msgs.msg import Clock

    tracker = start_node('tracker', '--ros-args', '-p', 'use_sim_time:=true')
    subscribe_outputs(collector)
    clock = collector.publisher(Clock, '/clock', 10)
    pub = collector.publisher(PointStamped, qos.OBSERVATION, qos.STATE)
    collector.wait_for_subscribers(pub)
    release = Release(model='full', position=(0.0, 0.0, 1.8))
    truth = Flight.from_release(release).simulate(rate=60.0)
    rng = np.random.default_rng(4)

    def throw(base, clock_at, n_landed):
        for k, (t, p) in enumerate(zip(truth.times[:-1], truth.positions[:-1])):
            if k % 6 == 0:
                clock.publish(_clock(clock_at))  # a stalled /clock: it never moves
            pub.publish(point(base + t, p + rng.normal(0.0, 0.02, 3)))
            time.sleep(0.004)
        deadline = time.monotonic() + 20.0
        while tracker.log().count('landed:') < n_landed and time.monotonic() < deadline:
            time.sleep(0.1)
        wait_until_quiet(collector, qos.LANDING)  # the node or this collector may lag

    for _ in range(10):
        clock.publish(_clock(1e6))
        time.sleep(0.05)
    throw(1000.0, 1e6, 1)  # a stranger's /clock at 1e6 s: predictions still at ~30 Hz of fixes
    n_first = len(collector.get(qos.LANDING))
    t_flight = float(truth.times[-1])
    # (the node clock's throttle gave a handful; frames may be lost on a busy machine)
    assert n_first > 0.4 * 30.0 * (t_flight - 0.1), (n_first, tracker.log())
    # The simulator restarted: /clock back at 50 s, the next throw stamped on it.
    collector.clear()
    for _ in range(10):
        clock.publish(_clock(50.0))
        time.sleep(0.05)
    throw(20.0, 50.0, 2)
    log = tracker.log()
    assert 'clock jumped back' in log and log.count('new throw') == 2, log
    landings = collector.get(qos.LANDING)
    assert len(landings) > 0.4 * 30.0 * (t_flight - 0.1), (len(landings), log)
    final = landings[-1]
    x_land, y_land = truth.positions[-1, :2]
    p = final.pose.pose.position
    assert math.hypot(p.x - x_land, p.y - y_land) < 0.15
    assert abs(stamp_s(final) - (20.0 + t_flight)) < 0.02
    assert 'Traceback' not in log


def test_the_camera_delivers_past_rate_times_latency_and_says_what_it_dropped(
    start_node, collector
):
    # 500 Hz x 0.6 s: 300 fixes in flight at once (the old queue of 256 published none).
    sim = start_node(
        'simulator',
        '--ros-args',
        '-p',
        'model:=full',
        '-p',
        'observation_rate:=500.0',
        '-p',
        'observation_latency:=0.6',
        '-p',
        'observation_dropout:=0.1',
        '-p',
        'hold_rate:=0.0',
    )
    collector.subscribe(PointStamped, qos.OBSERVATION, qos.STATE)
    collector.wait_for(
        lambda: collector.node.count_publishers('/' + qos.OBSERVATION) >= 1, 20.0, 'the camera'
    )
    time.sleep(0.5)
    release = Release(position=(0.0, 0.0, 1.8))
    order_flight(collector, release, 'camera-queue')
    collector.wait_for(lambda: len(landed_values(collector)) >= 1, 15.0, 'the landing')
    sim.wait_for_log('camera, flight 1 (landed)', 5.0)
    wait_until_quiet(collector, qos.OBSERVATION)
    t_flight = float(landed_values(collector)[0]['time_of_flight'])
    obs = collector.get(qos.OBSERVATION)
    # 90 % of the frames up to the landing, the last 0.6 s of them published at the landing.
    assert 0.85 * 500 * t_flight < len(obs) < 500 * t_flight + 10, (len(obs), sim.log())
    line = next(x for x in sim.log().splitlines() if 'camera, flight 1' in x)
    assert '0 dropped from a full queue' in line and '0 still waiting dropped' in line, line
    found = re.search(r'(\d+) of (\d+) fixes published \((\d+) at the landing\), (\d+) lost', line)
    published, captured, at_landing, dropout = (int(g) for g in found.groups())
    assert published + dropout == captured and published >= len(obs)
    assert at_landing == pytest.approx(0.9 * 0.6 * 500, abs=40)


def test_two_balls_get_a_stream_each(start_node, collector):
    # A receiver's plane x = 30 m, crossed along +x: the first ball goes through it.
    tracker = start_node(
        'tracker', '--ros-args', '-p', 'receiver_plane:=true', '-p', 'receiver_x:=30.0'
    )
    for k in (1, 2):
        collector.subscribe(
            PoseWithCovarianceStamped, qos.track_topic(k, qos.LANDING), qos.STATE
        )
    collector.subscribe(PoseWithCovarianceStamped, qos.LANDING, qos.STATE)
    collector.subscribe(PoseWithCovarianceStamped, qos.track_topic(2, qos.CATCH), qos.STATE)
    collector.subscribe(PoseWithCovarianceStamped, qos.track_topic(1, qos.RECEIVER), qos.STATE)
    pub = collector.publisher(PointStamped, qos.OBSERVATION, qos.STATE)
    collector.wait_for_subscribers(pub)
    first = Release(model='full', position=(0.0, 0.0, 1.8))
    second = Release(
        model='full', speed=20.0, elevation_deg=40.0, spin_rpm=-500.0, azimuth_deg=30.0,
        position=(10.0, 5.0, 1.5),
    )
    flights = [Flight.from_release(r).simulate(rate=60.0) for r in (first, second)]
    rng = np.random.default_rng(5)
    base = time.time() - 10.0
    fixes = [(base + t, p) for t, p in zip(flights[0].times[:-1], flights[0].positions[:-1])]
    fixes += [
        (base + 0.3 + t, p) for t, p in zip(flights[1].times[:-1], flights[1].positions[:-1])
    ]
    for k, (t, p) in enumerate(sorted(fixes, key=lambda f: f[0])):
        pub.publish(point(t, p + rng.normal(0.0, 0.02, 3)))
        if k % 4 == 0:
            time.sleep(0.01)
    deadline = time.monotonic() + 15.0
    while tracker.log().count('ended: landed') < 2 and time.monotonic() < deadline:
        time.sleep(0.1)
    for k in (1, 2):
        wait_until_quiet(collector, qos.track_topic(k, qos.LANDING))
    log = tracker.log()
    assert log.count('new throw') == 2 and log.count('ended: landed') == 2, log
    for k in (1, 2):  # one line at lock-on, one at the landing with the lock-on's error
        assert log.count(f'throw #{k} locked on') == 1 and log.count(f'throw #{k} landed:') == 1
        line = next(x for x in log.splitlines() if f'throw #{k} landed:' in x)
        assert float(re.search(r'was ([0-9.]+) m', line).group(1)) < 10.0, line
    for k, (flight, offset) in enumerate(zip(flights, (0.0, 0.3)), start=1):
        landings = collector.get(qos.track_topic(k, qos.LANDING))
        assert len(landings) > 20, (k, log)
        final = landings[-1]
        p = final.pose.pose.position
        x_land, y_land = flight.positions[-1, :2]
        assert math.hypot(p.x - x_land, p.y - y_land) < 0.15, (k, p)
        assert abs(stamp_s(final) - (base + offset + flight.times[-1])) < 0.02
    # The topics without an id carry the oldest live track: the first ball, then the second.
    legacy = collector.get(qos.LANDING)
    assert len(legacy) > 20 and 'Traceback' not in log
    # The second ball comes down through the default catch height 1.2 m where the flight does.
    catches = collector.get(qos.track_topic(2, qos.CATCH))
    assert len(catches) > 20
    z = flights[1].positions[:, 2]
    k = int(np.flatnonzero((z[:-1] >= 1.2) & (z[1:] < 1.2))[-1])
    final = catches[-1].pose.pose.position
    assert final.z == 1.2
    x_c, y_c = flights[1].positions[k, :2]  # within a 60 Hz sample of the crossing
    assert math.hypot(final.x - x_c, final.y - y_c) < 0.5
    t_c = base + 0.3 + flights[1].times[k]
    assert t_c - 0.02 < stamp_s(catches[-1]) < t_c + 1.0 / 60.0 + 0.02
    # The first ball through the receiver's plane, predicted before it got there (the last
    # prediction made before the crossing), with the y/z covariance of a point on the plane.
    x = flights[0].positions[:, 0]
    k = int(np.flatnonzero((x[:-1] < 30.0) & (x[1:] >= 30.0))[0])
    f = (30.0 - x[k]) / (x[k + 1] - x[k])
    t_w = flights[0].times[k] + f * (flights[0].times[k + 1] - flights[0].times[k])
    p_w = flights[0].positions[k] + f * (flights[0].positions[k + 1] - flights[0].positions[k])
    through = collector.get(qos.track_topic(1, qos.RECEIVER))
    assert len(through) > 10
    last = through[-1]
    p = last.pose.pose.position
    assert p.x == pytest.approx(30.0, abs=1e-6)
    assert math.hypot(p.y - p_w[1], p.z - p_w[2]) < 0.15, (p, p_w)
    assert abs(stamp_s(last) - (base + t_w)) < 0.02
    cov = np.array(last.pose.covariance).reshape(6, 6)
    assert cov[0, 0] == pytest.approx(0.0, abs=1e-9) and cov[1, 1] > 0.0 and cov[2, 2] > 0.0


def test_a_max_speed_below_min_speed_or_a_non_bool_unstable_fits_is_one_clear_line():
    import subprocess
    import sys

    def run(*params):
        args = [a for p in params for a in ('-p', p)]
        return subprocess.run(
            [sys.executable, '-m', 'football_ros.cli', 'tracker', '--ros-args', *args],
            capture_output=True, text=True, timeout=120)

    refused = run('max_speed:=2.0')  # below the filter's min_speed, 3 m/s
    assert refused.returncode == 2 and 'Traceback' not in refused.stderr
    assert "'max_speed' (2)" in refused.stderr and 'min_speed' in refused.stderr
    bad = run('unstable_fits:=maybe')  # a string for a bool: the parameter's type refused
    assert bad.returncode == 2 and 'unstable_fits' in bad.stderr + bad.stdout
