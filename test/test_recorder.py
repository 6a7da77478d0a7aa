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

"""Recorder, bag round trips (rosbags and, independently, mcap), signal safety, figures, demo."""

from pathlib import Path
import signal
import subprocess
import sys
import time
import types

from cli_run import run_cli
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from football_ros import bagfile
from football_ros.nodes import qos
from football_ros.nodes import recorder as recorder_node
from football_ros.nodes.topics import STATE_TOPICS
from football_ros.physics import Flight, Release
from geometry_msgs.msg import PoseStamped
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from rosutil import landed_event, order_flight
import yaml

STATE = STATE_TOPICS


def read_bag(path):
    counts, aero = {}, []
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for conn, _t, raw in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            if conn.topic == '/football/aero_angles':
                msg = reader.deserialize(raw, conn.msgtype)
                aero.append((msg.vector.x, msg.vector.y))
        msgdefs = {c.topic: c.msgdef.data for c in reader.connections}
    return counts, np.array(aero), msgdefs


def record_flight(start_node, collector, bag, storage, rate=1000.0):
    start_node('simulator', '--ros-args', '-p', f'publish_rate:={rate}', '-p', 'hold_rate:=0.0')
    recorder = start_node('record', '--out', str(bag), '--storage', storage)
    for topic in (qos.POSE, qos.AERO_ANGLES):  # the independent count (serialized: cheap)
        collector.subscribe(STATE[topic], topic, qos.STATE, raw=True)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    recorder.wait_for_log("recording '/diagnostics'")  # the simulator reaches the recorder
    order_flight(collector, Release(), 'bag-1')
    collector.wait_for(lambda: landed_event(collector), 15.0, 'the landing')
    time.sleep(0.5)
    assert recorder.stop(signal.SIGINT) == 0
    return recorder


def test_records_every_message_of_a_1khz_flight(start_node, collector, tmp_path):
    bag = tmp_path / 'bag'
    recorder = record_flight(start_node, collector, bag, 'mcap')
    counts, aero, msgdefs = read_bag(bag)
    expected = Flight.from_release(Release()).simulate(rate=1000.0, duration=10.0)
    for topic in (qos.POSE, qos.AERO_ANGLES):
        assert len(collector.get(topic)) == len(expected.times)  # the independent subscriber
    for topic in STATE:
        assert counts['/' + topic] == len(expected.times), (topic, counts)
    assert np.max(np.abs(aero - expected.aero_angles[:, :2])) < 1e-6
    assert '\nVector3 vector\n' in msgdefs['/football/aero_angles']  # the .msg as written
    assert '\nMSG: geometry_msgs/Vector3\n' in msgdefs['/football/aero_angles']
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['storage_identifier'] == 'mcap' and meta['message_count'] == sum(counts.values())
    assert meta['relative_file_paths'] == ['bag_0.mcap']  # as ros2 bag record names it
    # The definitions as rosbag2_cpp stores them: the installed .msg files with their comments.
    share = Path(sys.prefix) / 'share'
    pose_msg = (share / 'geometry_msgs' / 'msg' / 'PoseStamped.msg').read_text()
    assert msgdefs['/football/pose'].startswith(pose_msg + '\n' + '=' * 80 + '\n')
    assert msgdefs['/football/pose'].count('MSG: ') == 5  # Pose, Point, Quaternion, Header, Time
    topics = {
        t['topic_metadata']['name']: t['topic_metadata'] for t in meta['topics_with_message_count']
    }
    assert topics['/football/pose']['offered_qos_profiles'][0]['reliability'] == 'reliable'
    assert topics['/football/pose']['type'] == 'geometry_msgs/msg/PoseStamped'
    assert 'wrote' in recorder.log() and 'Traceback' not in recorder.log()
    # As ros2 bag record (jazzy) writes it: distro, and each topic's RIHS01 type hash equal to
    # the one its publisher advertises in the graph.
    assert meta['ros_distro'] == 'jazzy' and meta['version'] == 9
    assert not (bag / '.football_ros_reserve').exists()
    advertised = {}
    for name in topics:
        infos = collector.node.get_publishers_info_by_topic(name)
        if infos:
            advertised[name] = str(infos[0].topic_type_hash)
    assert {'/football/pose', '/football/odom', '/football/markers'} <= set(advertised)
    for name, digest in advertised.items():
        assert topics[name]['type_description_hash'] == digest, name
        assert digest.startswith('RIHS01_') and len(digest) == 7 + 64

    # Independently of rosbags: the mcap library with its ROS 2 decoder.
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with open(next(bag.glob('*.mcap')), 'rb') as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        by_topic = {
            ch.topic: summary.statistics.channel_message_counts[cid]
            for cid, ch in summary.channels.items()
        }
        assert by_topic['/football/odom'] == len(expected.times)
        assert reader.get_header().profile == 'ros2'
        [embedded] = [m for m in reader.iter_metadata() if m.name == 'rosbag2']
        assert 'ros_distro: jazzy' in embedded.metadata['serialized_metadata']
        for channel in summary.channels.values():
            schema = summary.schemas[channel.schema_id]
            assert channel.message_encoding == 'cdr' and schema.encoding == 'ros2msg'
            assert (
                channel.metadata['topic_type_hash']
                == topics[channel.topic]['type_description_hash']
            )
            qos_list = yaml.safe_load(channel.metadata['offered_qos_profiles'])
            assert qos_list and 'reliability' in qos_list[0]
        odom = [m.decoded_message for m in reader.iter_decoded_messages(topics=['/football/odom'])]
    positions = np.array(
        [[o.pose.pose.position.x, o.pose.pose.position.y, o.pose.pose.position.z] for o in odom]
    )
    assert np.max(np.abs(positions - expected.positions)) < 1e-6


def test_sqlite3_storage(start_node, collector, tmp_path):
    bag = tmp_path / 'bag_sqlite'
    record_flight(start_node, collector, bag, 'sqlite3', rate=200.0)
    counts, _, _ = read_bag(bag)
    assert (
        list(bag.glob('*.db3')) and counts['/football/pose'] == len(collector.get(qos.POSE)) == 560
    )
    import sqlite3

    with sqlite3.connect(next(bag.glob('*.db3'))) as db:
        assert db.execute('SELECT ros_distro FROM schema').fetchall() == [('jazzy',)]
        stored = yaml.safe_load(db.execute('SELECT metadata FROM metadata').fetchone()[0])
        hashes = dict(db.execute('SELECT name, type_description_hash FROM topics').fetchall())
    assert stored['ros_distro'] == 'jazzy' and stored['message_count'] == sum(counts.values())
    assert hashes['/football/pose'] == str(
        collector.node.get_publishers_info_by_topic('/football/pose')[0].topic_type_hash
    )


@pytest.mark.parametrize(
    'sig, after', [(signal.SIGINT, 0.3), (signal.SIGTERM, 1.1), (signal.SIGTERM, 0.0)]
)
def test_signal_at_any_moment_leaves_a_bag_that_opens(start_node, collector, tmp_path, sig, after):
    bag = tmp_path / 'bag'
    start_node('simulator', '--ros-args', '-p', 'publish_rate:=1000.0')
    recorder = start_node('record', '--out', str(bag))
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    recorder.wait_for_log("recording '/diagnostics'")  # the simulator reaches the recorder
    order_flight(collector, Release(), 'sig-1')
    if after >= 1.0:  # mid-flight with data flowing: after this many poses reached the test
        collector.wait_for(lambda: len(collector.get(qos.POSE)) >= 1000 * after, 10.0, 'poses')
    else:
        time.sleep(after)
    assert recorder.stop(sig) == 0, recorder.log()
    assert (bag / 'metadata.yaml').exists()
    counts, _, _ = read_bag(bag)
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['message_count'] == sum(counts.values())
    if after >= 1.0:
        assert counts.get('/football/pose', 0) > 500


def test_figures_from_csv_and_from_bag(tmp_path, start_node, collector):
    csv_path = tmp_path / 'flight.csv'
    Flight.from_release(Release(ball='rugby')).simulate(rate=200).write_csv(csv_path)
    bag = tmp_path / 'bag'
    record_flight(start_node, collector, bag, 'mcap', rate=200.0)
    for source, ball in ((csv_path, 'rugby'), (bag, 'american')):
        out = tmp_path / f'fig_{source.name}'
        proc = run_cli('plot', str(source), '--out', str(out), '--ball', ball, timeout=120)
        assert proc.returncode == 0, proc.stderr
        for name in ('wobble', 'angles', 'trajectory', 'precession'):
            png = out / f'{name}.png'
            assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and png.stat().st_size > 20_000


def test_flight_data_from_bag_matches_headless(tmp_path, start_node, collector):
    from football_ros.tools.flightdata import load

    bag = tmp_path / 'bag'
    record_flight(start_node, collector, bag, 'mcap', rate=200.0)
    record = load(bag)
    expected = Flight.from_release(Release()).simulate(rate=200.0)
    assert len(record.t) == len(expected.times)
    assert np.max(np.abs(record.velocity - expected.velocities)) < 1e-6
    assert np.max(np.abs(record.axis - expected.axes)) < 1e-9
    assert np.median(record.spin) == pytest.approx(600 * 2 * np.pi / 60, rel=1e-9)
    # The quasi-steady theory is in the bag as in a CSV (so plot draws it from either).
    quasi = expected.aero_angles_quasi_steady
    assert np.max(np.abs(record.alpha_quasi_steady - quasi[:, 0])) < 1e-9
    assert np.max(np.abs(record.beta_quasi_steady - quasi[:, 1])) < 1e-9
    if record.info is not None:  # the order reached the recorder: the title names its origin
        from football_ros.tools.figures import describe

        assert describe(record.info).endswith('(bag: football/flight/order)')


def test_plot_rejects_unknown_sources(tmp_path):
    (tmp_path / 'x.csv').write_text('a,b\n1,2\n')
    for source in (tmp_path / 'x.csv', tmp_path):
        proc = run_cli('plot', str(source), '--out', str(tmp_path / 'o'), timeout=60)
        assert proc.returncode == 2 and proc.stderr.count('\n') == 1


def test_demo_end_to_end(tmp_path):
    out = tmp_path / 'demo'
    proc = run_cli('demo', '--out', str(out), timeout=180)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert 'landed at x = 66.277 m' in proc.stdout
    progress = [
        line for line in proc.stdout.splitlines() if line.startswith('[demo]') and '  ' in line
    ]
    assert len(progress) > 20  # about ten lines per second of flight
    assert (out / 'bag' / 'metadata.yaml').exists()
    assert len(list((out / 'figures').glob('*.png'))) == 4
    for name in ('simulator', 'release', 'recorder'):
        assert 'Traceback' not in (out / f'{name}.log').read_text()


# --- parameters, params files, namespaces (issue 10.1, 10.3) -------------------------------------


def _config():
    return Path(__file__).resolve().parents[1] / 'config' / 'football.yaml'


def _params_file(tmp_path, body, key='/**/football_recorder'):
    path = tmp_path / 'params.yaml'
    path.write_text(f'{key}:\n  ros__parameters:\n' + ''.join(f'    {line}\n' for line in body))
    return path


@pytest.mark.parametrize('namespace', ['', '/team1'])
def test_shipped_params_file_under_any_namespace(start_node, tmp_path, namespace):
    """The shipped YAML starts the recorder (rcl reads [] as unset), also in a namespace."""
    bag = tmp_path / 'bag'
    args = ['--ros-args', '--params-file', str(_config()), '-p', f'output:={bag}']
    if namespace:
        args += ['-r', f'__ns:={namespace}']
    rec = start_node('record', *args)
    assert f'recording {len(recorder_node.TOPICS)} topics to {bag} (mcap)' in rec.log()
    assert rec.stop() == 0 and 'Traceback' not in rec.log()
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['message_count'] == 0 and meta['ros_distro'] == 'jazzy'


@pytest.mark.parametrize(
    'topics, expected',
    [
        ('[]', len(recorder_node.TOPICS)),
        ('[""]', len(recorder_node.TOPICS)),
        ('[football/pose, /diagnostics]', 2),
        ('football/odom', 1),
        (  # the tracker's, the camera's and the simulator's acknowledgements
            '[football/estimate, football/prediction/landing, football/prediction/path, '
            'football/observation, football/flight/ack]',
            5,
        ),
    ],
)
def test_namespaced_recorder_honours_output_and_topics(start_node, tmp_path, topics, expected):
    """Wildcard keys apply under -r __ns:=/team1; relative topics resolve in the namespace."""
    bag = tmp_path / 'team_bag'
    params = _params_file(tmp_path, [f'output: {bag}', 'storage: sqlite3', f'topics: {topics}'])
    rec = start_node('record', '--ros-args', '-r', '__ns:=/team1', '--params-file', str(params))
    assert f'recording {expected} topics to {bag} (sqlite3)' in rec.log()
    assert rec.stop() == 0
    assert list(bag.glob('*.db3')) and (bag / 'metadata.yaml').exists()


@pytest.mark.parametrize(
    'line, field',
    [
        ('topics: 5', 'topics'),
        ('topics: [1, 2]', 'topics'),
        ('output: 3', 'output'),
        ('storage: [mcap]', 'storage'),
        ('storage: rosbag', 'storage'),
        ('topics: [nope]', 'topics'),
        ("topics: ['bad name!']", 'topics'),
    ],
)
def test_bad_parameters_give_one_line_naming_the_field(tmp_path, line, field):
    params = _params_file(tmp_path, [f'output: {tmp_path / "bag"}', line])
    proc = run_cli('record', '--ros-args', '--params-file', str(params), timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert 'Traceback' not in proc.stderr and f"'{field}'" in proc.stderr
    assert proc.stderr.strip().count('\n') == 0, proc.stderr
    assert not (tmp_path / 'bag').exists()


# --- write errors: full disk, file size limit (issue 9.7) ----------------------------------------
def check_bag_consistent(bag):
    """Check that the bag opens with rosbags and the mcap reader, and every count agrees."""
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    counts, _, _ = read_bag(bag)
    assert meta['message_count'] == sum(counts.values())
    per_topic = {
        t['topic_metadata']['name']: t['message_count'] for t in meta['topics_with_message_count']
    }
    assert {k: v for k, v in per_topic.items() if v} == counts
    if meta['storage_identifier'] != 'mcap':
        return meta, counts
    from mcap.reader import make_reader

    with open(bag / meta['relative_file_paths'][0], 'rb') as handle:
        reader = make_reader(handle)
        summary = reader.get_summary()
        stats = {
            summary.channels[cid].topic: n
            for cid, n in summary.statistics.channel_message_counts.items()
            if n
        }
        assert stats == counts
        read = {}
        for _schema, channel, _message in reader.iter_messages():
            read[channel.topic] = read.get(channel.topic, 0) + 1
        assert read == counts
    return meta, counts


@pytest.fixture
def small_disk(tmp_path):
    """Mount a tmpfs of the recorder's reserve + 1.5 MiB (root with mount rights only)."""
    disk = tmp_path / 'disk'
    disk.mkdir()
    size = recorder_node.RESERVE_BYTES + (3 << 19)
    proc = subprocess.run(
        ['mount', '-t', 'tmpfs', '-o', f'size={size}', 'tmpfs', str(disk)],
        capture_output=True,
        text=True,
    )
    if proc.returncode != 0:
        pytest.skip(f'cannot mount a tmpfs here: {proc.stderr.strip()}')
    yield disk
    subprocess.run(['umount', '-l', str(disk)], capture_output=True)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_full_disk_keeps_the_recording(start_node, collector, small_disk, storage):
    bag = small_disk / 'bag'
    start_node('simulator', '--ros-args', '-p', 'publish_rate:=1000.0')
    recorder = start_node('record', '--out', str(bag), '--storage', storage)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE, raw=True)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    recorder.wait_for_log("recording '/diagnostics'")
    # The recorder's ERROR status can only reach a reader it has discovered: wait for both
    # /diagnostics publishers (simulator, recorder) before the disk fills up.
    collector.wait_for(
        lambda: collector.node.count_publishers(qos.DIAGNOSTICS) >= 2, 20.0, 'the publishers'
    )
    time.sleep(0.5)
    order_flight(collector, Release(), 'full-1')
    recorder.proc.wait(timeout=30)  # the disk fills up within the flight: the recorder ends
    log = recorder.log()
    assert recorder.proc.returncode == 1, log
    assert 'Traceback' not in log
    errors = [line for line in log.splitlines() if line.startswith('[ERROR]')]
    assert len(errors) == 1, log
    assert 'No space left on device' in errors[0] or 'database or disk is full' in errors[0], log
    meta, counts = check_bag_consistent(bag)
    assert counts['/football/pose'] > 300  # about 1.5 MiB of a 1 kHz flight was kept
    assert counts['/football/pose'] <= len(collector.get(qos.POSE))
    assert f'recording stopped after {meta["message_count"]} messages' in errors[0]
    assert not (bag / recorder_node.RESERVE_NAME).exists()
    statuses = [
        s
        for arr in collector.get(qos.DIAGNOSTICS)
        for s in arr.status
        if s.name == recorder_node.DIAGNOSTIC_NAME
    ]
    assert len(statuses) == 1 and statuses[0].level == DiagnosticStatus.ERROR
    assert statuses[0].hardware_id == '/football_recorder'


def test_file_size_limit_drops_only_what_is_not_on_disk(tmp_path, monkeypatch):
    """
    A write error that persists after the reserve is freed (EFBIG: a file size limit).

    The messages not yet on disk are dropped, the rest is closed into a consistent bag.
    """
    import errno

    from rosbags.rosbag2 import StoragePlugin

    limit = 3 << 20
    original = bagfile._File.write

    def limited(self, data):
        if self.tell() + len(memoryview(data).cast('B')) > limit:
            raise OSError(errno.EFBIG, 'File too large')
        return original(self, data)

    monkeypatch.setattr(bagfile._File, 'write', limited)
    typestore = get_typestore(Stores.ROS2_JAZZY)
    writer = bagfile.BagWriter(
        tmp_path / 'bag', version=9, storage_plugin=StoragePlugin.MCAP
    )
    writer.open()
    conn = writer.add_connection(
        '/football/pose', 'geometry_msgs/msg/PoseStamped', typestore=typestore
    )
    writer.add_connection(
        '/diagnostics', 'diagnostic_msgs/msg/DiagnosticArray', typestore=typestore
    )
    msg = typestore.types['geometry_msgs/msg/PoseStamped']
    header = typestore.types['std_msgs/msg/Header']
    stamp = typestore.types['builtin_interfaces/msg/Time']
    point = typestore.types['geometry_msgs/msg/Point']
    quat = typestore.types['geometry_msgs/msg/Quaternion']
    pose = typestore.types['geometry_msgs/msg/Pose']
    written, failed = 0, None
    for i in range(100_000):
        data = typestore.serialize_cdr(
            msg(
                header(stamp(i, 0), 'field' * 40),
                pose(point(float(i), 0.0, 0.0), quat(0, 0, 0, 1)),
            ),
            'geometry_msgs/msg/PoseStamped',
        )
        writer.write(conn, 1000 + i, data)
        written += 1
        try:
            writer.checkpoint()
        except OSError as exc:
            failed = exc
            break
    assert failed is not None and failed.errno == errno.EFBIG
    assert (tmp_path / 'bag' / 'bag_0.mcap').stat().st_size <= limit
    lost, error = writer.close_after_error()
    assert error is None and 0 < lost < written
    meta, counts = check_bag_consistent(tmp_path / 'bag')
    assert counts == {'/football/pose': written - lost} and meta['ros_distro'] == 'jazzy'
    with AnyReader([tmp_path / 'bag'], default_typestore=typestore) as reader:
        xs = [
            reader.deserialize(raw, c.msgtype).pose.position.x for c, _t, raw in reader.messages()
        ]
    assert xs == [float(i) for i in range(written - lost)]  # the first ones, in order, intact


# --- use_sim_time (issue 10.6) ----------------------------------------------------------------
def test_recorder_under_sim_time_stamps_with_clock(start_node, collector, tmp_path):
    """
    use_sim_time:=true.

    Receive times are /clock time (as ros2 bag record --use-sim-time), i.e. the simulated time
    of the tick that published the message.
    """
    bag = tmp_path / 'sim_bag'
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_rate:=200.0',
        '-p',
        'publish_clock:=true',
        '-p',
        'real_time_factor:=2.0',
        '-p',
        'hold_rate:=0.0',
    )
    recorder = start_node(
        'record',
        '--out',
        str(bag),
        '--topics',
        'football/pose',
        '/diagnostics',
        '/clock',
        '--ros-args',
        '-p',
        'use_sim_time:=true',
    )
    recorder.wait_for_log("recording '/diagnostics'")
    order_flight(collector, Release(), 'sim-time')
    collector.wait_for(lambda: landed_event(collector), 15.0, 'the landing')
    time.sleep(0.3)
    assert recorder.stop() == 0
    pairs = []
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for conn, t, raw in reader.messages(
            connections=[c for c in reader.connections if c.topic == '/football/pose']
        ):
            stamp = reader.deserialize(raw, conn.msgtype).header.stamp
            pairs.append((t, stamp.sec * 1_000_000_000 + stamp.nanosec))
    expected = Flight.from_release(Release()).simulate(rate=100.0)  # 2 x 1/200 s per tick
    assert len(pairs) == len(expected.times)
    received, stamps = np.array(pairs).T
    assert np.all(np.diff(stamps) == 10_000_000) and stamps[-1] < 600e9  # simulated time
    lag = (received - stamps) * 1e-9
    assert np.median(np.abs(lag)) <= 0.010 and np.max(np.abs(lag)) < 0.5, (lag.min(), lag.max())
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['starting_time']['nanoseconds_since_epoch'] < 600e9


class _FakeNode:
    """Stands in for rclpy's Node.declare_parameter: returns the value rcl would give."""

    def __init__(self, value):
        self._value = value

    def declare_parameter(self, name, value, descriptor):
        assert descriptor.dynamic_typing and descriptor.read_only
        return types.SimpleNamespace(value=self._value)


_PARAM_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(),
    st.text(max_size=30),
    st.lists(st.text(max_size=20), max_size=5),
    st.lists(st.integers(), max_size=3),
    st.lists(st.floats(), max_size=3),
    st.lists(st.booleans(), max_size=3),
    st.binary(max_size=5),
)


@settings(max_examples=300, deadline=None)
@given(_PARAM_VALUES)
def test_parameter_values_fuzz_give_a_value_or_an_error_naming_the_field(value):
    """Whatever a params file gives (rcl types: unset, bool, int, float, str, arrays, bytes)."""
    specs = {spec.name: spec for spec in recorder_node.PARAMETERS}
    for name in ('topics', 'output'):
        try:
            got = specs[name].declare(_FakeNode(value))
        except ValueError as exc:
            assert f"'{name}'" in str(exc)
            continue
        if name == 'topics':  # the node then drops the empty names: [''] = every topic
            assert isinstance(got, list) and all(isinstance(t, str) for t in got)
            expected = [''] if value is None else [value] if isinstance(value, str) else value
            assert got == expected
        else:
            assert got == ('' if value is None else value) and isinstance(got, str)


def test_a_spawned_balls_topics_are_recorded_and_echoed(start_node, collector, tmp_path):
    """A ball spawned on the running simulator: the default recording and echo take its topics."""
    srv = pytest.importorskip('simulation_interfaces.srv', reason='simulation_interfaces')
    from rosutil import call

    start_node('simulator', '--ros-args', '-p', 'hold_rate:=20.0')
    bag = tmp_path / 'spawned'
    recorder = start_node('record', '--out', str(bag))
    request = srv.SpawnEntity.Request(name='ball2', uri='football_ros://rugby')
    request.initial_pose = PoseStamped()
    request.initial_pose.pose.position.x, request.initial_pose.pose.position.z = 3.5, 1.25
    request.initial_pose.pose.orientation.w = 1.0
    response = call(collector, srv.SpawnEntity, '/football_simulator/spawn_entity', request, 30.0)
    assert response.entity_name == 'ball2', response.result.error_message
    echoed = run_cli('echo', qos.entity_topic('ball2', 'odom'), '--count', '1', '--timeout', '60')
    assert echoed.returncode == 0, echoed.stderr
    odom = yaml.safe_load(echoed.stdout.split('---')[0])
    assert odom['pose']['pose']['position'] == {'x': 3.5, 'y': 0.0, 'z': 1.25}
    assert odom['child_frame_id'].endswith('ball2')
    for leaf in ('pose', 'odom'):
        recorder.wait_for_log(f"recording '/football/ball2/{leaf}' (first message received)")
    assert recorder.stop(signal.SIGINT) == 0
    counts, _, msgdefs = read_bag(bag)
    assert counts['/football/ball2/pose'] >= 1 and counts['/football/ball2/odom'] >= 1, counts
    assert msgdefs['/football/ball2/odom'].startswith('# This represents an estimate')
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic == '/football/ball2/pose']
        poses = [reader.deserialize(raw, c.msgtype) for c, _t, raw in reader.messages(conns)]
    assert all((p.pose.position.x, p.pose.position.z) == (3.5, 1.25) for p in poses)


def test_an_unknown_topic_is_refused_naming_the_patterns(tmp_path):
    proc = run_cli('record', '--out', str(tmp_path / 'b'), '--topics', 'football/b/twist',
                   timeout=120)
    assert proc.returncode == 2 and "unknown topic 'football/b/twist'" in proc.stderr
    assert 'football/<entity>/pose' in proc.stderr
