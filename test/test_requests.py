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

"""Release-request parser and flight orders (no ROS): contract, bad input, property-based fuzz."""

import json
import math

from football_ros.physics import Release
from football_ros.requests import (
    FlightOrder,
    load_strict,
    ORDER_KEYS,
    parse_release_request,
    RequestError,
    StrictParseError,
)
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
import pytest
import yaml


def test_defaults_and_id():
    rid, release = parse_release_request('{id: pass-1}')
    assert rid == 'pass-1' and release == Release()
    rid2, release2 = parse_release_request('{}')
    assert rid2.startswith('req-') and release2 == Release()


@pytest.mark.parametrize('text', ['', '   \n', 'null', '~', '---\n'])
def test_an_empty_request_is_refused_not_flown(text):
    with pytest.raises(RequestError, match='must be one mapping of release keys, got an empty'):
        parse_release_request(text)


@pytest.mark.parametrize('raw', ['', 'a\x00b', 'x' * 129, 'req-7', 'id-0123456789abcdef', 12])
def test_an_unusable_id_is_answered_under_the_documented_hash(raw):
    import hashlib
    import json

    expected = raw if raw == 12 else 'id-' + hashlib.sha256(raw.encode()).hexdigest()[:16]
    if raw == 12:  # a usable integer id: its text
        assert parse_release_request(json.dumps({'id': raw}))[0] == '12'
        return
    with pytest.raises(RequestError) as info:
        parse_release_request(json.dumps({'id': raw}))
    assert info.value.request_id == expected
    assert info.value.request_id != raw


def test_yaml_and_json_forms_are_equivalent():
    text_yaml = (
        'id: 7\nball: rugby\nspeed: 22.5\nspin_rpm: -400\nposition: [1, 2, 0.5]\n'
        'ball_params: {c_m_alpha: 0.2}'
    )
    text_json = json.dumps(
        {
            'id': 7,
            'ball': 'rugby',
            'speed': 22.5,
            'spin_rpm': -400,
            'position': [1, 2, 0.5],
            'ball_params': {'c_m_alpha': 0.2},
        }
    )
    a, b = parse_release_request(text_yaml), parse_release_request(text_json)
    assert a == b and a[0] == '7' and a[1].preset().c_m_alpha == 0.2


@pytest.mark.parametrize(
    'text, reason',
    [
        ('{id: x, speed: .nan}', 'must be a number'),
        ('{id: x, speed: 1e999}', 'finite'),
        ('{id: x, speed: 0x14}', 'must be a number'),
        ('{id: x, speed: 2_0}', 'must be a number'),
        ('{id: x, speed: 1' + '0' * 60 + '}', 'digits'),
        ('{id: x, spin_rpm: ' + '9' * 39 + '}', 'outside'),
        ('{id: x, speed: 20, speed: 21}', 'duplicate key'),
        ('{id: x, speed: !!float 20}', 'tags'),
        ('{id: x, ball_params: !!binary aGk=}', 'tags'),
        ('{id: x, position: !!set {a, b}}', 'tags'),
        ('{id: x, speed: 2001-01-01}', 'must be a number'),
        ('{id: x, alpha0_deg: 55, beta0_deg: 55}', 'axis offset'),
        ('{id: x, aero: {wind: [[[1]]]}}', 'nested'),
        ('{id: x, speed: -1}', 'outside'),
        ('{id: x, speed: 1e9}', 'outside'),
        ('{id: x, spin_rpm: 99999}', 'outside'),
        ('{id: x, elevation_deg: 91}', 'outside'),
        ('{id: x, beta0_deg: -75}', 'outside'),
        ('{id: x, ball: soccer}', 'unknown ball preset'),
        ('{id: x, colour: red}', 'unknown key'),
        ('{id: x, speed: fast}', 'must be a number'),
        ('{id: x, speed: [1, 2]}', 'must be a number'),
        ('{id: x, position: [0, 0]}', 'position'),
        ('{id: x, model: warp}', "'model' must be one of paper, full"),
        ('{id: x, ball_params: {mass: zero}}', 'ball parameter'),
        ('{id: x, ball_params: [1]}', 'mapping'),
        ('{id: x, ball: 3}', "'ball' must be a preset name"),
    ],
)
def test_bad_values_keep_the_id_and_name_the_problem(text, reason):
    with pytest.raises(RequestError, match=reason) as info:
        parse_release_request(text)
    assert info.value.request_id == 'x'


@pytest.mark.parametrize(
    'text, reason',
    [
        ('id: [unclosed', 'malformed'),
        ('- just\n- a list', 'mapping'),
        ('42', 'mapping'),
        ('a: &x [1]\nb: *x', 'aliases'),
        ('!!python/object:os.system {}', 'tags'),
        ('<<: {speed: 20}', 'merge keys'),
        ('{id: a}\n---\n{id: b}', 'single'),
        ('[' * 30000 + ']' * 30000, 'nest'),
        ('{? [a] : 1}', 'key must be a string'),
        ('{1: 2}', 'string'),
        ('{id: [1, 2]}', "'id'"),
        ('x' * 70000, 'bytes'),
    ],
)
def test_unreadable_requests_get_a_made_up_id(text, reason):
    with pytest.raises(RequestError, match=reason) as info:
        parse_release_request(text)
    assert info.value.request_id.startswith('req-')


def test_flight_order_round_trip_keeps_the_state():
    release = Release(
        ball='rugby',
        alpha0_deg=3.0,
        beta_rate_deg_s=12.0,
        azimuth_deg=-20.0,
        position=(1.0, -2.0, 1.5),
        moment='sin2delta',
    )
    order = FlightOrder.from_release('rt', release)
    back = FlightOrder.from_json(order.to_json())
    assert back.request_id == 'rt' and back.moment == 'sin2delta' and back.ball_name == 'rugby'
    for name in ('position', 'velocity', 'axis', 'transverse_rate', 'attitude'):
        assert np.allclose(getattr(back.initial, name), getattr(order.initial, name), atol=1e-12)
    assert back.initial.spin == pytest.approx(order.initial.spin, rel=1e-12)


@pytest.mark.parametrize(
    'text',
    [
        '[]',
        '{}',
        'not json',
        json.dumps(
            {
                'id': 'a',
                'model': 'paper',
                'moment': 'linear',
                'ball': 'american',
                'position': [0, 0, 0],
                'velocity': [1e9, 0, 0],
                'orientation': [0, 0, 0, 1],
                'angular_velocity': [0, 0, 0],
            }
        ),
    ],
)
def test_bad_flight_orders_raise_value_error(text):
    with pytest.raises(ValueError):
        FlightOrder.from_json(text)


# --- property-based fuzz -------------------------------------------------------------------
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-(10**12), 10**12))
values = st.one_of(
    numbers,
    st.text(max_size=20),
    st.none(),
    st.booleans(),
    st.lists(numbers, max_size=4),
    st.dictionaries(st.text(max_size=8), numbers, max_size=3),
)
keys = st.sampled_from(list(Release.FIELDS) + ['id', 'bogus', ''])


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


def _offset_deg(alpha0, beta0):
    """Total angle between axis and velocity of an (alpha0, beta0) offset [deg]."""
    return math.degrees(math.acos(math.cos(math.radians(alpha0)) * math.cos(math.radians(beta0))))


@settings(max_examples=200, deadline=None)
@given(
    st.floats(1.0, 60.0),
    st.floats(-80.0, 80.0).filter(lambda e: e > 0.5),
    st.floats(-3000.0, 3000.0),
    st.floats(-60.0, 60.0),
    st.floats(-60.0, 60.0),
    st.floats(-3600.0, 3600.0),
    st.floats(-3600.0, 3600.0),
)
def test_fuzz_valid_ranges_are_accepted_and_every_accepted_release_is_a_valid_order(
    speed, elevation, spin, alpha0, beta0, alpha_rate, beta_rate
):
    """
    One truth: a release accepted field by field is also accepted as a flight order.

    And the combined limits (total axis offset, transverse rate) decide exactly as the order's
    do.
    """
    text = json.dumps(
        {
            'id': 'ok',
            'speed': speed,
            'elevation_deg': elevation,
            'spin_rpm': spin,
            'alpha0_deg': alpha0,
            'beta0_deg': beta0,
            'alpha_rate_deg_s': alpha_rate,
            'beta_rate_deg_s': beta_rate,
        }
    )
    release = _outcome(text)
    combined_ok = (
        _offset_deg(alpha0, beta0) <= 60.0 and math.hypot(alpha_rate, beta_rate) <= 3600.0
    )
    if release is None:
        assert (
            not combined_ok
            or min(
                abs(_offset_deg(alpha0, beta0) - 60.0),
                abs(math.hypot(alpha_rate, beta_rate) - 3600.0),
            )
            < 1e-6
        )
        return
    assert math.isclose(release.speed, speed)
    order = FlightOrder.from_release('ok', release, 'o-1')
    back = FlightOrder.from_json(order.to_json())
    assert back.order_id == 'o-1' and np.allclose(back.initial.velocity, order.initial.velocity)


@pytest.mark.parametrize(
    'speed, elevation', [(60.0, 80.0), (60.0, -80.0), (1.0, 80.0), (60.0, 45.0)]
)
def test_edges_of_the_ranges_survive_the_hand_off(speed, elevation):
    """Round-off in the derived state must not refuse a release at the edge of a range."""
    release = Release(
        speed=speed,
        elevation_deg=elevation,
        position=(0.0, 0.0, 2.0),
        spin_rpm=3000.0,
        alpha0_deg=60.0,
    )
    assert (
        FlightOrder.from_json(FlightOrder.from_release('e', release).to_json()).request_id == 'e'
    )


@pytest.mark.parametrize(
    'patch, reason',
    [
        ({'velocity': [1e308, 1e308, 0]}, 'speed'),
        ({'velocity': 'fast'}, 'velocity'),
        ({'orientation': [0, 0, 0, 0]}, 'unit quaternion'),
        ({'position': [0, 0, -1]}, 'position'),
        ({'ball_params': {'mass': 0}}, 'mass'),
        ({'model': 'warp'}, 'model'),
        ({'aero': {'c_d0': 1}}, 'model: full'),
        ({'extra': 1}, 'unknown flight-order key'),
        ({'id': ''}, "'id'"),
        ({'angular_velocity': [1e400, 0, 0]}, 'finite'),
    ],
)
def test_bad_orders_name_the_field(patch, reason):
    data = json.loads(FlightOrder.from_release('b', Release()).to_json())
    data.update(patch)
    with pytest.raises(ValueError, match=reason):
        FlightOrder.from_json(json.dumps(data).replace('Infinity', '1e400'))


# --- the strict request language --------------------------------------------------------------
json_scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.floats(allow_nan=False, allow_infinity=False),
    st.text(st.characters(blacklist_categories=('Cs',)), max_size=20),
)
json_data = st.recursive(
    json_scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5),
        st.dictionaries(
            st.text(st.characters(blacklist_categories=('Cs',)), max_size=8), inner, max_size=5
        ),
    ),
    max_leaves=12,
)


def _depth(value) -> int:
    if isinstance(value, dict):
        return 1 + max((_depth(v) for v in value.values()), default=0)
    if isinstance(value, list):
        return 1 + max((_depth(v) for v in value), default=0)
    return 0


@settings(max_examples=400, deadline=None)
@given(json_data)
def test_fuzz_json_reads_as_json_does(data):
    """Every JSON document within the limits reads exactly as json.loads reads it."""
    text = json.dumps(data)
    if _depth(data) > 4:
        with pytest.raises(ValueError, match='nest'):
            load_strict(text)
        return
    assert load_strict(text) == json.loads(text)


@settings(max_examples=400, deadline=None)
@given(st.text(max_size=200))
def test_fuzz_any_text_is_read_or_refused_with_a_reason(text):
    try:
        value = load_strict(text)
    except StrictParseError as exc:
        assert str(exc) and isinstance(exc.partial, dict)
        return
    assert isinstance(value, (dict, list, str, int, float, bool, type(None)))


order_values = st.one_of(
    json_scalars,
    st.lists(json_scalars, max_size=5),
    st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=4),
    st.dictionaries(
        st.sampled_from(['mass', 'c_m_alpha', 'wind', 'drag', 'x']), json_scalars, max_size=3
    ),
)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(st.sampled_from(ORDER_KEYS + ('extra',)), order_values, max_size=4))
def test_fuzz_flight_orders_are_flown_or_refused_with_a_reason(patch):
    """The hand-off's one validation: a mutated order is a flyable FlightOrder or a ValueError."""
    data = json.loads(FlightOrder.from_release('f', Release()).to_json())
    data.update(patch)
    try:
        order = FlightOrder.from_json(json.dumps(data))
        flight = order.flight(0.001)
    except ValueError as exc:
        assert str(exc)
        return
    sample = flight.sample(0.05)
    assert np.all(np.isfinite(sample.position)) and np.all(np.isfinite(sample.aero_angles))


@given(
    st.sampled_from(['speed', 'elevation_deg', 'spin_rpm', 'azimuth_deg', 'alpha0_deg']),
    st.floats(allow_nan=False, allow_infinity=False),
)
@settings(max_examples=300, deadline=None)
def test_a_refusal_quotes_the_refused_value_exactly(key, value):
    from football_ros.physics.release import LIMITS

    lo, hi = LIMITS[key]
    text = json.dumps({'id': 'exact', key: value})
    if lo <= value <= hi:
        return
    with pytest.raises(RequestError) as info:
        parse_release_request(text)
    message = str(info.value)
    quoted = message.split(f"'{key}' = ", 1)[1].split(' is outside', 1)[0]
    assert float(quoted) == value, message  # reads back as the very float refused


def test_a_value_just_outside_the_range_is_not_rounded_into_it():
    with pytest.raises(RequestError) as info:
        parse_release_request('{speed: 60.00002}')
    assert "'speed' = 60.00002 is outside the accepted range [1, 60]" in str(info.value)
    with pytest.raises(RequestError, match=r"'spin_rpm' = -3000.0000000000005 is outside"):
        parse_release_request('{spin_rpm: -3000.0000000000005}')
