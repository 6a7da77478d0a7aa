"""Release-request parser and flight orders (no ROS): contract, bad input, property-based fuzz."""

import json
import math

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from football_ros.physics import Release
from football_ros.requests import FlightOrder, RequestError, parse_release_request


def test_defaults_and_id():
    rid, release = parse_release_request("{id: pass-1}")
    assert rid == "pass-1" and release == Release()
    rid2, _ = parse_release_request("")
    assert rid2.startswith("req-")


def test_yaml_and_json_forms_are_equivalent():
    text_yaml = "id: 7\nball: rugby\nspeed: 22.5\nspin_rpm: -400\nposition: [1, 2, 0.5]\nball_params: {c_m_alpha: 0.2}"
    text_json = json.dumps({"id": 7, "ball": "rugby", "speed": 22.5, "spin_rpm": -400,
                            "position": [1, 2, 0.5], "ball_params": {"c_m_alpha": 0.2}})
    a, b = parse_release_request(text_yaml), parse_release_request(text_json)
    assert a == b and a[0] == "7" and a[1].preset().c_m_alpha == 0.2


@pytest.mark.parametrize("text, reason", [
    ("{id: x, speed: .nan}", "finite"), ("{id: x, speed: .inf}", "finite"),
    ("{id: x, speed: -1}", "outside"), ("{id: x, speed: 1e9}", "outside"),
    ("{id: x, spin_rpm: 99999}", "outside"), ("{id: x, elevation_deg: 91}", "outside"),
    ("{id: x, beta0_deg: -75}", "outside"), ("{id: x, ball: soccer}", "unknown ball preset"),
    ("{id: x, colour: red}", "unknown key"), ("{id: x, speed: fast}", "must be a number"),
    ("{id: x, speed: [1, 2]}", "must be a number"), ("{id: x, position: [0, 0]}", "position"),
    ("{id: x, model: warp}", "unknown model"), ("{id: x, ball_params: {mass: zero}}", "ball parameter"),
    ("{id: x, ball_params: [1]}", "mapping"), ("{id: x, ball: 3}", "must be a string"),
])
def test_bad_values_keep_the_id_and_name_the_problem(text, reason):
    with pytest.raises(RequestError, match=reason) as info:
        parse_release_request(text)
    assert info.value.request_id == "x"


@pytest.mark.parametrize("text, reason", [
    ("id: [unclosed", "malformed"), ("- just\n- a list", "mapping"), ("42", "mapping"),
    ("a: &x [1]\nb: *x", "aliases"), ("!!python/object:os.system {}", "malformed"),
    ("{1: 2}", "string"), ("{id: [1, 2]}", "'id'"), ("{id: ''}", "'id'"),
    ("x" * 70000, "bytes"), ("{id: \"a\\x00b\"}", "printable"),
])
def test_unreadable_requests_get_a_made_up_id(text, reason):
    with pytest.raises(RequestError, match=reason) as info:
        parse_release_request(text)
    assert info.value.request_id.startswith("req-")


def test_flight_order_round_trip_keeps_the_state():
    release = Release(ball="rugby", alpha0_deg=3.0, beta_rate_deg_s=12.0, azimuth_deg=-20.0,
                      position=(1.0, -2.0, 1.5), moment="sin2delta")
    order = FlightOrder.from_release("rt", release)
    back = FlightOrder.from_json(order.to_json())
    assert back.request_id == "rt" and back.moment == "sin2delta" and back.ball_name == "rugby"
    for name in ("position", "velocity", "axis", "transverse_rate", "attitude"):
        assert np.allclose(getattr(back.initial, name), getattr(order.initial, name), atol=1e-12)
    assert back.initial.spin == pytest.approx(order.initial.spin, rel=1e-12)


@pytest.mark.parametrize("text", ["[]", "{}", "not json", json.dumps({"id": "a", "model": "paper",
                                  "moment": "linear", "ball": "american", "position": [0, 0, 0],
                                  "velocity": [1e9, 0, 0], "orientation": [0, 0, 0, 1],
                                  "angular_velocity": [0, 0, 0]})])
def test_bad_flight_orders_raise_value_error(text):
    with pytest.raises(ValueError):
        FlightOrder.from_json(text)


# --- property-based fuzz -------------------------------------------------------------------
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**12, 10**12))
values = st.one_of(numbers, st.text(max_size=20), st.none(), st.booleans(),
                   st.lists(numbers, max_size=4), st.dictionaries(st.text(max_size=8), numbers, max_size=3))
keys = st.sampled_from(list(Release.FIELDS) + ["id", "bogus", ""])


def _outcome(text):
    """Parse; the only allowed outcomes are a valid release or a RequestError with a reason."""
    try:
        rid, release = parse_release_request(text)
    except RequestError as exc:
        assert str(exc) and exc.request_id
        return None
    state = release.initial_state()
    assert np.all(np.isfinite(state.velocity)) and abs(np.linalg.norm(state.axis) - 1) < 1e-12
    assert 1.0 <= release.speed <= 60.0 and abs(release.spin_rpm) <= 3000.0
    assert rid
    return release


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(keys, values, max_size=6))
def test_fuzz_structured_requests(mapping):
    try:
        text = json.dumps(mapping, allow_nan=True)
    except (TypeError, ValueError):
        return
    _outcome(text)
    _outcome(yaml.safe_dump(mapping))


@settings(max_examples=400, deadline=None)
@given(st.text(max_size=300))
def test_fuzz_arbitrary_text(text):
    _outcome(text)


@settings(max_examples=200, deadline=None)
@given(st.floats(1.0, 60.0), st.floats(-80.0, 80.0).filter(lambda e: e > 0.5),
       st.floats(-3000.0, 3000.0), st.floats(-60.0, 60.0), st.floats(-60.0, 60.0))
def test_fuzz_valid_ranges_are_accepted(speed, elevation, spin, alpha0, beta0):
    text = json.dumps({"id": "ok", "speed": speed, "elevation_deg": elevation, "spin_rpm": spin,
                       "alpha0_deg": alpha0, "beta0_deg": beta0})
    release = _outcome(text)
    assert release is not None and math.isclose(release.speed, speed)
