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

"""``football-ros plan``: its JSON flown by ``simulate --plan``, refusals, ``--throw``."""

import csv
import json
import math
import subprocess
import sys

from football_ros.command_line import UsageError
from football_ros.physics import dynamics as dyn
from football_ros.physics.presets import PRESETS
from football_ros.physics.release import Release
from football_ros.planning.planner import closest_approach
from football_ros.tools.plan import release_from_plan
from hypothesis import given, settings, strategies as hs
import numpy as np
import pytest
import yaml

CLI = [sys.executable, '-m', 'football_ros.cli']
RELEASE_KEYS = ('speed', 'elevation_deg', 'azimuth_deg', 'spin_rpm', 'alpha0_deg', 'beta0_deg',
                'alpha_rate_deg_s', 'beta_rate_deg_s')


def run(*args, check=True, timeout=120):
    proc = subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=timeout)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def simulate_options(p: dict) -> list[str]:
    """Return the plan's JSON keys as simulate options, key by key (--key with dashes)."""
    argv = ['--ball', p['ball'], '--model', p['model']]
    for key in RELEASE_KEYS:
        argv += [f'--{key.replace("_", "-")}', repr(p[key])]
    argv += ['--position', *map(repr, p['position'])]
    if p['aero'].get('wind'):
        argv += ['--wind', *map(repr, p['aero']['wind'])]
    return argv


def test_plan_json_flown_by_simulate_passes_within_1cm(tmp_path):
    target = [33.0, -4.0, 1.4]
    proc = run('plan', '--target', *map(str, target), '--position', '0', '0', '1.8',
               '--model', 'full', '--wind', '3', '4', '0', '--spin-rpm', '-600',
               '--objective', 'flat', '--hit-n', '500', '--json')
    p = json.loads(proc.stdout)
    for key in (*RELEASE_KEYS, 'arrival_time', 'miss_m', 'wobble_deg', 'aligned_wobble_deg'):
        assert isinstance(p[key], float), key
    assert p['miss_m'] < 0.01 and p['wobble_deg'] < 0.2 * p['aligned_wobble_deg']
    assert p['spin_rpm'] == -600.0 and p['speed'] == pytest.approx(27.4)
    assert 0.0 < p['hit_probability_low'] <= p['hit_probability'] <= p['hit_probability_high']
    plan_file = tmp_path / 'plan.json'
    plan_file.write_text(proc.stdout)
    out = tmp_path / 'flight.csv'
    run('simulate', '--plan', str(plan_file), '--rate', '1000', '--out', str(out))
    by_options = tmp_path / 'by_options.csv'
    run('simulate', *simulate_options(p), '--rate', '1000', '--out', str(by_options))
    assert out.read_bytes() == by_options.read_bytes()  # the file flies the plan's release
    with open(out) as handle:
        rows = list(csv.DictReader(handle))
    states = np.zeros((len(rows), dyn.N_STATE))
    times = np.array([float(r['t']) for r in rows])
    for i, name in enumerate(('x', 'y', 'z')):
        states[:, dyn.R + i] = [float(r[name]) for r in rows]
        states[:, dyn.V + i] = [float(r['v' + name]) for r in rows]
    miss, t_arr, _ = closest_approach(times, states, np.array(target))
    assert miss < 0.01
    assert t_arr == pytest.approx(p['arrival_time'], abs=2e-3)


def test_simulate_plan_refuses_a_bad_file_naming_it(tmp_path):
    bad = tmp_path / 'bad.json'
    bad.write_text('{"speed": 20.0}')
    proc = run('simulate', '--plan', str(bad), '--out', str(tmp_path / 'x.csv'), check=False)
    assert proc.returncode == 2 and 'Traceback' not in proc.stderr
    assert f'--plan {bad}: no ball, elevation_deg' in proc.stderr
    proc = run('simulate', '--plan', str(bad), '--speed', '3', '--out', str(tmp_path / 'x.csv'),
               check=False)
    assert proc.returncode == 2 and 'drop --speed' in proc.stderr
    assert not (tmp_path / 'x.csv').exists()


@settings(max_examples=200, deadline=None)
@given(hs.one_of(
    hs.binary(max_size=300),
    hs.dictionaries(hs.sampled_from(Release.FIELDS + ('extra',)), hs.one_of(
        hs.none(), hs.booleans(), hs.floats(), hs.text(max_size=5),
        hs.lists(hs.floats(), max_size=4), hs.dictionaries(hs.text(max_size=3), hs.floats(),
                                                           max_size=2))).map(
        lambda d: json.dumps(d).encode())))
def test_release_from_plan_reads_any_file_or_names_the_fault(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp('plan') / 'plan.json'
    path.write_bytes(raw)
    try:
        release = release_from_plan(str(path))
    except UsageError as exc:
        assert str(exc).startswith(f'--plan {path}: ')
    else:
        assert math.isfinite(release.speed) and release.ball in PRESETS


def test_plan_table_and_refusals():
    proc = run('plan', '--target', '25', '0', '0', '--hit-n', '0')
    assert 'wobble amplitude' in proc.stdout and 'turning with it' in proc.stdout
    proc = run('plan', '--target', '300', '0', '1', '--max-speed', '30', check=False)
    assert proc.returncode == 1 and proc.stdout == ''
    err = proc.stderr.strip()
    assert 'out of reach' in err and 'max_speed' in err and 'closest reachable point' in err
    proc = run('plan', '--target', '20', '0', '-2', check=False)
    assert proc.returncode == 1 and 'below the ground' in proc.stderr
    proc = run('plan', '--target', '20', 'nan', '1', check=False)
    assert proc.returncode == 1 and 'finite' in proc.stderr
    proc = run('plan', check=False)
    assert proc.returncode == 2 and 'exactly one of --target and --receiver' in proc.stderr
    proc = run('plan', '--target', '20', '0', check=False)
    assert proc.returncode == 2


def test_plan_compare_arcs():
    proc = run('plan', '--target', '35', '0', '0.5', '--position', '0', '0', '1.8', '--model',
               'full', '--compare-arcs', '--hit-n', '1000', '--json')
    arcs = json.loads(proc.stdout)['arcs']
    assert arcs['flat_elevation_deg'] < 30.0 < arcs['lofted_elevation_deg']
    assert arcs['flat_arrival_time'] < arcs['lofted_arrival_time']
    for arc in ('flat', 'lofted'):
        assert 0.0 < arcs[f'{arc}_hit_probability_low'] < arcs[f'{arc}_hit_probability_high']
    assert arcs['more_robust'] in ('flat', 'lofted', 'either')


def test_plan_receiver_is_led():
    proc = run('plan', '--receiver', '25', '0', '1.2', '0', '5', '0', '--objective', 'flat',
               '--hit-n', '0', '--json')
    p = json.loads(proc.stdout)
    expected = np.array([25.0, 5.0 * p['arrival_time'], 1.2])
    assert np.linalg.norm(np.array(p['arrival_point']) - expected) < 0.01


def test_plan_throw_through_the_release_node_and_the_simulator(start_node, collector):
    """The planned throw sent to the real nodes: the simulator's landing within 1 cm."""
    from football_ros.nodes import qos
    from diagnostic_msgs.msg import DiagnosticArray

    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    start_node('simulator')
    start_node('release')
    target = (28.0, 3.0, 0.0)  # on the ground: the simulator reports its landing point
    proc = run('plan', '--target', *map(str, target), '--model', 'full', '--wind', '-2', '1',
               '0', '--hit-n', '0', '--json', '--throw', '--id', 'planned-1')
    first, rest = proc.stdout.split('\n', 1)
    plan_json = json.loads(first)
    answer = yaml.safe_load(rest)
    assert answer['name'] == 'planned-1' and answer['level'] == 0
    values = {kv['key']: kv['value'] for kv in answer['values']}
    assert float(values['landing_x']) == pytest.approx(target[0], abs=0.01)
    assert float(values['landing_y']) == pytest.approx(target[1], abs=0.01)

    def landing():
        for arr in collector.get(qos.DIAGNOSTICS):
            for st in arr.status:
                kv = {k.key: k.value for k in st.values}
                if kv.get('flight_id') == 'planned-1' and 'landing_x' in kv:
                    return float(kv['landing_x']), float(kv['landing_y'])
        return None

    collector.wait_for(lambda: landing() is not None, plan_json['arrival_time'] + 20.0,
                       'the landed event')
    x, y = landing()
    assert np.hypot(x - target[0], y - target[1]) < 0.01
