"""Release node across processes: contract, bad input on the wire, the typed state path, a flood."""

import json
import math
import time
from collections import Counter
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from football_ros.nodes import qos
from football_ros.physics import Flight, Release

OK, WARN, ERROR = 0, 1, 2  # DiagnosticStatus levels (bytes in rclpy, compared as ints)
REQUIRED_VALUES = {"omega_fast", "omega_slow", "critical_spin_rpm", "equilibrium_sideslip", "stable",
                   "time_of_flight", "range"}


def level(status):
    return status.level[0] if isinstance(status.level, bytes) else status.level


def values(status):
    return {kv.key: kv.value for kv in status.values}


@pytest.fixture
def client(collector):
    collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.requests = collector.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
    collector.states = collector.publisher(Odometry, qos.RELEASE_STATE, qos.REQUEST)
    return collector


def ask(client, texts, timeout=20.0):
    """Publish request texts; return the responses that arrive for them (in arrival order)."""
    client.wait_for_subscribers(client.requests)
    before = len(client.get(qos.RELEASE_RESPONSE))
    for text in texts:
        client.requests.publish(String(data=text))
    client.wait_for(lambda: len(client.get(qos.RELEASE_RESPONSE)) >= before + len(texts), timeout,
                    f"{len(texts)} responses")
    time.sleep(0.2)  # anything extra would show up now
    return client.get(qos.RELEASE_RESPONSE)[before:]


def connect(client, timeout=30.0):
    """Probe until the release node accepts (it has discovered the simulator); drop the probes.

    Right after start-up DDS discovery may still drop a request (or the release node may not
    see the simulator yet), so a probe without an OK answer is sent again."""
    client.wait_for_subscribers(client.requests)
    deadline = time.monotonic() + timeout
    k = 0
    while time.monotonic() < deadline:
        k += 1
        name = f"probe-{k}"
        client.requests.publish(String(data=f"{{id: {name}}}"))
        answered = time.monotonic() + 2.0
        while time.monotonic() < answered:
            answers = [r for r in client.get(qos.RELEASE_RESPONSE) if r.name == name]
            if answers:
                break
            time.sleep(0.02)
        if answers and level(answers[0]) == OK:
            client.wait_for(lambda: client.get(qos.POSE), 10.0, "the probe flight")
            time.sleep(0.3)  # late answers to earlier probes
            client.clear()
            return
    raise AssertionError("the release node never accepted a probe")


def test_accepted_request_flies_and_answers_with_the_prediction(start_node, client):
    start_node("simulator")
    start_node("release")
    connect(client)
    [resp] = ask(client, ['{id: pass-1, ball: american, speed: 25, spin_rpm: 650}'])
    assert resp.name == "pass-1" and level(resp) == OK and "accepted" in resp.message
    vals = values(resp)
    assert REQUIRED_VALUES <= set(vals)
    expected = Flight.from_release(Release(speed=25.0, spin_rpm=650.0))
    assert float(vals["omega_fast"]) == pytest.approx(expected.modes.omega_fast, rel=1e-12)
    assert float(vals["time_of_flight"]) == pytest.approx(2 * 25 * 0.5 / 9.81, abs=1e-9)
    assert float(vals["range"]) == pytest.approx(25 ** 2 * math.sin(math.radians(60)) / 9.81, abs=1e-6)
    assert vals["stable"] == "true"
    client.wait_for(lambda: len(client.get(qos.POSE)) > 10, 10.0, "the simulator's poses")
    # Gyroscopically unstable release: accepted with WARN.
    [warn] = ask(client, ['{"id": "slow-spin", "spin_rpm": 200}'])
    assert level(warn) == WARN and "unstable" in warn.message and values(warn)["stable"] == "false"


def test_without_simulator_the_answer_says_so(start_node, client):
    start_node("release")
    client.wait_for_subscribers(client.requests)
    for k in range(10):  # a request lost to discovery right after start-up is sent again
        client.requests.publish(String(data=f"{{id: lonely-{k}}}"))
        try:
            client.wait_for(lambda: client.get(qos.RELEASE_RESPONSE), 2.0, "an answer")
            break
        except AssertionError:
            continue
    resp = client.get(qos.RELEASE_RESPONSE)[0]
    assert resp.name.startswith("lonely-") and level(resp) == ERROR
    assert "no simulator is listening" in resp.message


BAD_REQUESTS = [
    ("{id: b1, speed: .nan}", "b1", "finite"),
    ("{id: b2, speed: -.inf}", "b2", "finite"),
    ("{id: b3, speed: -12}", "b3", "outside"),
    ("{id: b4, speed: 3000}", "b4", "outside"),
    ("{id: b5, spin_rpm: 1e7}", "b5", "outside"),
    ("{id: b6, alpha0_deg: 170}", "b6", "outside"),
    ("{id: b7, ball: basketball}", "b7", "unknown ball preset"),
    ("{id: b8, sped: 20}", "b8", "unknown key"),
    ("{id: b9, speed: '20'}", "b9", "must be a number"),
    ("{id: b10, position: [0, 0, -3]}", "b10", "outside"),
    ("{id: b11, model: full, aero: {c_d0: -1}}", "b11", "outside"),
    ("{id: b12, aero: {drag: false}}", "b12", "need model: full"),
    ("{id: [oops", None, "malformed"),
    ("[1, 2, 3]", None, "mapping"),
    ("!!python/object/apply:os.system ['echo pwned']", None, "malformed"),
    ("a: &a [1]\nb: *a", None, "aliases"),
    ("x" * 100000, None, "bytes"),
]


def test_each_bad_input_class_gets_one_error_and_nothing_else_changes(start_node, client):
    simulator = start_node("simulator")
    release = start_node("release")
    connect(client)
    flights_before = simulator.log().count("released at")
    responses = ask(client, [text for text, _, _ in BAD_REQUESTS])
    assert len(responses) == len(BAD_REQUESTS)
    for (text, rid, reason), resp in zip(BAD_REQUESTS, responses):
        assert level(resp) == ERROR, (text[:40], resp.message)
        assert reason in resp.message, (text[:40], resp.message)
        assert resp.name == rid if rid else resp.name.startswith("req-")
    assert simulator.log().count("released at") == flights_before  # no flight was started
    log = release.log()
    assert log.count("rejected") >= len(BAD_REQUESTS) and "Traceback" not in log
    assert not Path("pwned").exists()
    [good] = ask(client, ["{id: after}"])
    assert level(good) == OK


def _state_request(release: Release, sec: int, ball: str = "american") -> Odometry:
    st = release.initial_state()
    msg = Odometry(child_frame_id=ball)
    msg.header.frame_id = "field"
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, 5
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = map(float, st.position)
    q.x, q.y, q.z, q.w = map(float, st.attitude)
    lin, ang = msg.twist.twist.linear, msg.twist.twist.angular
    lin.x, lin.y, lin.z = map(float, st.velocity)
    ang.x, ang.y, ang.z = map(float, st.angular_velocity())
    return msg


def test_typed_state_request(start_node, client):
    start_node("simulator")
    start_node("release")
    connect(client)
    client.wait_for_subscribers(client.states)
    release = Release(ball="rugby", alpha0_deg=2.0, beta_rate_deg_s=-15.0)
    client.states.publish(_state_request(release, 42, "rugby"))
    bad = _state_request(release, 43, "rugby")
    bad.twist.twist.linear.x = math.nan
    client.states.publish(bad)
    client.states.publish(_state_request(release, 44, "frisbee"))
    client.wait_for(lambda: len(client.get(qos.RELEASE_RESPONSE)) >= 3, 10.0, "3 responses")
    by_id = {r.name: r for r in client.get(qos.RELEASE_RESPONSE)}
    ok = by_id["state:42.000000005"]
    assert level(ok) == OK
    expected = Flight.from_release(release)
    assert float(values(ok)["equilibrium_sideslip"]) == pytest.approx(expected.modes.equilibrium_sideslip,
                                                                       rel=1e-9)
    assert float(values(ok)["omega_slow"]) == pytest.approx(expected.modes.omega_slow, rel=1e-9)
    assert level(by_id["state:43.000000005"]) == ERROR and "finite" in by_id["state:43.000000005"].message
    assert level(by_id["state:44.000000005"]) == ERROR and "preset" in by_id["state:44.000000005"].message


def _rss_kb(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def test_flood_every_request_answered_once_memory_bounded(start_node, client):
    start_node("simulator")
    release = start_node("release")
    connect(client)
    rss_before = _rss_kb(release.pid)
    rate, seconds = 300, 3.0
    sent = []
    start = time.monotonic()
    for k in range(int(rate * seconds)):
        rid = f"flood-{k}"
        text = (json.dumps({"id": rid, "speed": 15 + k % 20, "spin_rpm": 300 + k % 500}) if k % 3
                else f"{{id: {rid}, speed: -{k}}}")
        client.requests.publish(String(data=text))
        sent.append(rid)
        time.sleep(max(0.0, start + (k + 1) / rate - time.monotonic()))
    client.wait_for(lambda: len(client.get(qos.RELEASE_RESPONSE)) >= len(sent), 30.0, "all responses")
    time.sleep(0.3)
    names = Counter(r.name for r in client.get(qos.RELEASE_RESPONSE) if r.name.startswith("flood-"))
    assert set(names) == set(sent) and set(names.values()) == {1}
    levels = Counter(level(r) for r in client.get(qos.RELEASE_RESPONSE) if r.name.startswith("flood-"))
    assert levels[ERROR] == len(sent) // 3 and levels[OK] + levels[WARN] == len(sent) - len(sent) // 3
    growth_mb = (_rss_kb(release.pid) - rss_before) / 1024
    assert growth_mb < 30, f"release node grew by {growth_mb:.1f} MB during the flood"
    t0 = time.monotonic()
    [after] = ask(client, ["{id: still-there}"])
    assert level(after) == OK and time.monotonic() - t0 < 2.0
