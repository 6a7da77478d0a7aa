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
Viewer node: a Foxglove WebSocket server for the package's topics and a 3D scene; no RViz needed.

``football-ros view [--port 8765] [--host 127.0.0.1] [--bag BAG]`` and ``ros2 run football_ros
view`` are the same node. Open Foxglove or Lichtblick on ``ws://HOST:PORT`` (layout:
``config/foxglove_layout.json``).

Live: every football_ros topic on the domain (those of nodes/topics.py, each spawned ball's
``football/<name>/pose`` and ``/odom``, each track's ``football/track_<n>/...``) is offered as a
channel of ROS 2 messages (encoding ``cdr``, schema ``ros2msg``: the definition ``ros2 bag
record`` stores), as foxglove_bridge offers them; the node subscribes to a topic only while a
viewer subscribes to its channel (best effort: the publishers keep no history for a viewer).
``/football/scene`` (``foxglove.SceneUpdate``, JSON) draws every ball as its spheroid at its
attitude with its spin axis, velocity and trail, each landing prediction with its 95 % ellipse,
the predicted and planned paths, and the field's lines (football_ros/scene.py).

``--bag BAG``: the bag's topics and the scene from its states, with the viewer's time controls
(play, pause, seek, speed).

Bounded: each viewer has a queue of ``backlog`` messages (the oldest dropped when a viewer does
not read); the queue overflows, the viewers and the forwarded counts go to /diagnostics once a
second. Live, one thread forwards: it waits on the viewed topics' readers itself and hands
every message's CDR bytes to the server untouched (no executor, no decoding); the scene (or
the bag's player) runs in another, decoding the newest message of each source once per update.
Bound to another address than the loopback, the node warns that every machine that reaches it
sees the topics (the protocol has no authentication).
"""

from __future__ import annotations

import argparse
from collections import deque
import ipaddress
import json
import logging
import os
from pathlib import Path
import socket
import sys
import threading
import time
import traceback
from typing import Sequence

from diagnostic_msgs.msg import DiagnosticArray
import foxglove
from foxglove import Channel, Schema
from foxglove.websocket import Capability, PlaybackState, PlaybackStatus
from rclpy.callback_groups import CallbackGroup
from rclpy.guard_condition import GuardCondition
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from . import messages as mb
from . import qos
from .logs import throttled
from .params import declare_all, ParamSpec
from .quiet import QuietNode
from .runner import run_node
from .topics import TOPICS, type_name
from ..bagfile import msgdef
from ..physics import PRESETS
from ..playback import Bag, BagError, PlaybackClock
from ..scene import Scene, scene_role, SceneError, SCHEMA, SCHEMA_NAME

NODE_NAME = 'football_view'
SCENE_TOPIC = '/football/scene'
DISCOVERY_S = 0.5
DIAGNOSTICS_S = 1.0
TIME_BROADCAST_S = 0.05
MAX_CHANNELS = 2048
"""Most topics served: more are left out (counted on /diagnostics)."""
VIEW_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                      reliability=ReliabilityPolicy.BEST_EFFORT)
"""The viewer's readers: best effort (a reliable publisher keeps nothing for it), 100 deep."""
KNOWN_TYPES = {type_name(cls): cls for cls, _ in TOPICS.values()}
FORWARD_WAIT_NS = 500_000_000
"""Longest wait of the forwarder [ns] (a change of the viewed topics wakes it at once)."""

PARAMETERS = (
    ParamSpec('host', '127.0.0.1', 'Address to serve on (another than the loopback: a warning)',
              read_only=True, non_empty=True),
    ParamSpec('port', 8765, 'WebSocket port (0 = any free port, logged)', limits=(0, 65535),
              read_only=True),
    ParamSpec('bag', '', "Bag folder to serve instead of the live topics; '' = live",
              read_only=True, optional=True),
    ParamSpec('topics', [''], "Topics to offer; unset, [] or [''] = every football_ros topic",
              read_only=True, optional=True),
    ParamSpec('ball', 'american', 'Ball preset the scene draws (its length and diameter)',
              choices=tuple(PRESETS), read_only=True),
    ParamSpec('scene_rate', 20.0, 'Scene updates per second [Hz]', limits=(1.0, 100.0),
              read_only=True),
    ParamSpec('backlog', 1024, 'Messages queued per viewer; the oldest dropped past it',
              limits=(16, 100000), read_only=True),
)


class _Overflows(logging.Handler):
    """
    Counts the SDK's reports of a viewer's full queue (each: its oldest messages dropped).

    The SDK reports a full queue once per episode, not per message; warnings and errors of the
    SDK go on to ``log`` (the node's logger).
    """

    def __init__(self, log) -> None:
        super().__init__(logging.INFO)
        self.count = 0
        self._log = log

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        if 'outbox' in text and 'full' in text:
            self.count += 1
        elif record.levelno >= logging.WARNING:
            self._log.warning(f'foxglove: {text[:300]}')


class _Forwarded(CallbackGroup):
    """The forwarder's subscriptions: no executor waits on them or runs them."""

    def can_execute(self, entity) -> bool:
        return False

    def beginning_execution(self, entity) -> bool:
        return False

    def ending_execution(self, entity) -> None:
        pass


def _unused(_data: bytes) -> None:
    """Stand for the callback of a forwarded subscription (the forwarder takes its messages)."""


class ViewNode(QuietNode):
    """Serves the football_ros topics and a 3D scene to Foxglove viewers over WebSocket."""

    PARAMETERS = PARAMETERS

    def __init__(self, host: str | None = None, port: int | None = None,
                 bag: str | None = None) -> None:
        super().__init__(NODE_NAME)
        declare_all(self, PARAMETERS)
        self.host = host or self.host
        self.port = self.port if port is None else int(port)
        if not 0 <= self.port <= 65535:
            raise ValueError(f"'port' must be in [0, 65535], got {self.port}")
        bag_path = bag or self.bag
        self._lock = threading.Lock()
        self._requests: deque = deque(maxlen=10000)  # (op, channel id) from the server thread
        self._channels: dict[str, Channel] = {}  # topic -> channel
        self._types: dict[str, str] = {}  # topic -> ROS type
        self._by_id: dict[int, str] = {}  # channel id -> topic
        self._viewers: dict[str, set[int]] = {}  # topic -> subscribed client ids
        # topic -> (class, channel, scene source): the forwarder's subscriptions, replaced whole
        self._wanted_subs: dict[str, tuple] = {}
        self._subscribed = 0  # subscriptions the forwarder holds
        self._forwarded_group = _Forwarded()
        self._wake = GuardCondition(None, None, self.context)  # wakes the forwarder
        self._scene_lock = threading.Lock()
        self._latest: dict[str, bytes] = {}  # scene source topic -> newest message
        self._removed: list[str] = []  # scene parts to delete (their topics retired)
        self._roles: dict[str, tuple[str, str]] = {}  # scene source topic -> (role, name)
        self._forwarded = self._left_out = self._refused = self._scenes = 0
        self._refusal = ''
        preset = PRESETS[self.ball]
        self._scene = Scene(preset.length, preset.diameter)
        self._prefix = self.resolve_topic_name('football') + '/'
        self._wanted = set()
        for name in (t for t in self.topics if t):
            try:
                self._wanted.add(self.resolve_topic_name(name))
            except Exception as exc:  # noqa: BLE001 - rclpy raises its own types for a bad name
                raise ValueError(f"parameter 'topics': invalid topic name '{name[:200]}'"
                                 ) from exc
        self._overflows = _Overflows(self.get_logger())
        sdk_log = logging.getLogger('foxglove')
        sdk_log.setLevel(logging.INFO)
        sdk_log.propagate = False  # its lines go to _Overflows only
        sdk_log.addHandler(self._overflows)
        foxglove.set_log_level('INFO')  # the SDK's log records reach Python's logging
        self._bag = self._playhead = self._seek_to = None
        self._commanded = False  # a viewer has used the time controls
        if bag_path:
            try:
                self._bag = Bag(bag_path)
            except BagError as exc:
                raise ValueError(f"parameter 'bag': {exc}") from None
            self._playhead = PlaybackClock(self._bag.start_ns, self._bag.end_ns)
            self._seek_to = self._bag.start_ns
        self._scene_channel = Channel(
            SCENE_TOPIC, message_encoding='json',
            schema=Schema(name=SCHEMA_NAME, encoding='jsonschema',
                          data=json.dumps(SCHEMA).encode()),
        )
        self._by_id[self._scene_channel.id()] = SCENE_TOPIC
        self._guard = self.create_guard_condition(self._apply_requests)
        capabilities = [Capability.Time] if self._bag else []
        try:
            self.server = foxglove.start_server(
                name='football_ros', host=self.host, port=self.port,
                capabilities=capabilities, server_listener=self,
                supported_encodings=['cdr', 'json'], message_backlog_size=self.backlog,
                playback_time_range=(
                    (self._bag.start_ns, self._bag.end_ns) if self._bag else None),
            )
        except Exception as exc:  # noqa: BLE001 - the SDK raises its own error types
            raise ValueError(f'cannot serve on {self.host}:{self.port}: {exc}') from None
        self.url = f'ws://{self.host}:{self.server.port}'
        if not no_delay(self.server.port):
            self.get_logger().warning(
                'could not set TCP_NODELAY on the server socket: a viewer may get small '
                'messages up to one delayed acknowledgement (about 40 ms) late')
        self._diag_pub = self.create_publisher(DiagnosticArray, qos.DIAGNOSTICS,
                                               qos.DIAGNOSTICS_QOS)
        self.create_timer(DIAGNOSTICS_S, self._diagnose)
        if self._bag:
            for topic in self._bag.topics.values():
                self._offer(topic.name, topic.ros_type, topic.definition)
        else:
            self.create_timer(DISCOVERY_S, self._discover)
            self._discover()
        # The forwarder and the scene (or the bag's player) work in their own threads: the
        # executor only takes the viewers' requests; a thread that wants the interpreter
        # gets it back within 0.5 ms.
        sys.setswitchinterval(5e-4)
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._play if self._bag else self._live,
                                          name='football-view', daemon=True)]
        if not self._bag:
            self._threads.append(threading.Thread(target=self._forward,
                                                  name='football-view-forward', daemon=True))
        for thread in self._threads:
            thread.start()
        if not _loopback(self.host):
            self.get_logger().warning(
                f'serving on {self.host}: every machine that reaches this address sees the '
                'football_ros topics (the Foxglove protocol has no authentication); '
                '--host 127.0.0.1 keeps it on this machine'
            )
        source = f"the bag '{self._bag.path}'" if self._bag else 'the live topics'
        self.get_logger().info(f'ready: serving {source} on {self.url}')

    # --- channels -------------------------------------------------------------------------
    def _offer(self, topic: str, ros_type: str, definition: str = '') -> None:
        """Advertise ``topic`` to the viewers (once)."""
        if topic in self._channels:
            return
        if len(self._channels) >= MAX_CHANNELS:
            self._left_out += 1
            return
        try:
            definition = definition or msgdef(ros_type)
        except OSError:
            self._left_out += 1
            return
        channel = Channel(topic, message_encoding='cdr',
                          schema=Schema(name=ros_type, encoding='ros2msg',
                                        data=definition.encode()))
        with self._lock:
            self._channels[topic] = channel
            self._types[topic] = ros_type
            self._by_id[channel.id()] = topic
        if topic.startswith(self._prefix):
            role = scene_role(topic[len(self._prefix):], ros_type)
            if role is not None:
                self._roles[topic] = role

    def _retire(self, topic: str) -> None:
        """Close the channel of a topic no node publishes any more; forget its scene part."""
        self._want(self._wanted_subs.keys() - {topic})
        with self._lock:
            channel = self._channels.pop(topic)
            self._by_id.pop(channel.id(), None)
            self._viewers.pop(topic, None)
        channel.close()
        role = self._roles.pop(topic, None)
        with self._scene_lock:
            self._latest.pop(topic, None)
            if role is not None and role[0] != 'velocity':
                self._removed.append(role[1])

    def _discover(self) -> None:
        """Offer every football_ros topic with publishers; retire the ones without."""
        seen = set()
        for topic, types in self.get_topic_names_and_types():
            if len(types) != 1 or types[0] not in KNOWN_TYPES:
                continue
            ours = topic.startswith(self._prefix) or topic in (qos.TF, qos.DIAGNOSTICS, qos.CLOCK)
            if not ours or (self._wanted and topic not in self._wanted):
                continue
            if self.count_publishers(topic) > 0:  # /diagnostics: this node's own at least
                seen.add(topic)
                self._offer(topic, types[0])
        for topic in [t for t in self._channels if t not in seen]:
            self._retire(topic)
        self._apply_requests()

    # --- the server's callbacks (its own threads): queue, wake the executor ---------------
    def on_subscribe(self, client, channel) -> None:
        """Take a viewer's subscription to a channel."""
        self._requests.append(('+', client.id, channel.id))
        self._guard.trigger()

    def on_unsubscribe(self, client, channel) -> None:
        """Take a viewer's unsubscription from a channel (or its leaving)."""
        self._requests.append(('-', client.id, channel.id))
        self._guard.trigger()

    def on_playback_control_request(self, request) -> PlaybackState | None:
        """Play, pause, seek and speed of the bag's player."""
        if self._playhead is None:
            return None
        with self._lock:
            clock = self._playhead
            self._commanded = True
            if request.seek_time is not None:
                clock.seek(request.seek_time)
                self._seek_to = clock.position()
            clock.set_speed(request.playback_speed)
            if request.playback_command.name == 'Play':
                clock.play()
            else:
                clock.pause()
            return self._playback_state(request.request_id, request.seek_time is not None)

    def _playback_state(self, request_id: str | None, did_seek: bool) -> PlaybackState:
        clock = self._playhead
        status = (PlaybackStatus.Ended if clock.ended and clock.playing
                  else PlaybackStatus.Playing if clock.playing else PlaybackStatus.Paused)
        return PlaybackState(status=status, current_time=clock.position(),
                             playback_speed=clock.speed, did_seek=did_seek,
                             request_id=request_id)

    # --- subscriptions (executor thread) --------------------------------------------------
    def _apply_requests(self) -> None:
        while self._requests:
            op, client, channel_id = self._requests.popleft()
            topic = self._by_id.get(channel_id)
            if topic is None:
                continue
            clients = self._viewers.setdefault(topic, set())
            (clients.add if op == '+' else clients.discard)(client)
        if self._bag is not None:
            if not self._commanded and any(self._viewers.values()):
                with self._lock:  # the first viewer starts the player (its controls rule after)
                    self._playhead.play()
                    self._commanded = True
            return
        scene = bool(self._viewers.get(SCENE_TOPIC))
        self._want({topic for topic in self._channels
                    if self._viewers.get(topic) or (scene and topic in self._roles)})

    def _want(self, topics: set[str]) -> None:
        """Ask the forwarder for subscriptions to exactly ``topics`` (executor thread)."""
        wanted = {t: (KNOWN_TYPES[self._types[t]], self._channels[t], t in self._roles)
                  for t in topics}
        if wanted != self._wanted_subs:
            self._wanted_subs = wanted
            self._wake.trigger()

    # --- the forwarder (its own thread): subscriptions, bytes to the channels ---------------
    def _forward(self) -> None:
        """
        Wait on the viewed topics' subscriptions and hand every message to its channel.

        The thread owns the subscriptions (created, waited on, destroyed only here): no
        executor sees them (their callback group runs nothing), and each wake-up takes every
        message each ready reader holds, as CDR bytes, straight to the server.
        """
        subs: dict[str, tuple] = {}  # topic -> (subscription, class, channel, scene source)
        wait_set = applied = None
        while not self._stop.is_set():
            try:
                wanted = self._wanted_subs
                if wanted is not applied:
                    self._reconcile(subs, wanted)
                    applied = wanted
                    wait_set = _rclpy.WaitSet(len(subs), 1, 0, 0, 0, 0, self.context.handle)
                self._forward_once(subs, wait_set)
            except Exception:  # noqa: BLE001 - the node goes on, as after a callback's error
                if not self.context.ok():  # shut down under the thread: nothing to clean
                    return
                throttled(self.get_logger(), 'error',
                          f'the forwarder failed (it goes on):\n{traceback.format_exc()}', 10.0)
                applied = None  # the subscriptions and the wait set again
                self._stop.wait(0.1)
        if self.context.ok():
            self._reconcile(subs, {})

    def _forward_once(self, subs: dict, wait_set) -> None:
        """Wait (at most :data:`FORWARD_WAIT_NS`) and forward what the ready readers hold."""
        wait_set.clear_entities()
        for sub, _, _, _ in subs.values():
            wait_set.add_subscription(sub.handle)
        wait_set.add_guard_condition(self._wake.handle)
        wait_set.wait(FORWARD_WAIT_NS)
        ready = wait_set.get_ready_entities('subscription')
        if not ready:
            return
        for topic, (sub, cls, channel, scene_source) in subs.items():
            if sub.handle.pointer not in ready:
                continue
            take, data = sub.handle.take_message, None
            while (taken := take(cls, True)) is not None:
                data = taken[0]
                channel.log(data, log_time=time.time_ns())
                self._forwarded += 1
            if scene_source and data is not None:
                with self._scene_lock:
                    self._latest[topic] = data

    def _reconcile(self, subs: dict, wanted: dict) -> None:
        """Create and destroy subscriptions until ``subs`` holds the ``wanted`` topics."""
        for topic in [t for t in subs if t not in wanted]:
            self.destroy_subscription(subs.pop(topic)[0])
            with self._scene_lock:
                self._latest.pop(topic, None)
        for topic, (cls, channel, scene_source) in wanted.items():
            if topic in subs:  # a topic retired and offered again: its new channel
                subs[topic] = (subs[topic][0], cls, channel, scene_source)
                continue
            sub = self.create_subscription(cls, topic, _unused, VIEW_QOS, raw=True,
                                           callback_group=self._forwarded_group)
            subs[topic] = (sub, cls, channel, scene_source)
        self._subscribed = len(subs)

    # --- the scene (the worker thread) -----------------------------------------------------
    def _feed(self, topic: str, data: bytes) -> None:
        """Give the scene one message of a scene source topic (refusals counted)."""
        role, name = self._roles.get(topic) or (None, None)
        cls = KNOWN_TYPES.get(self._types.get(topic, ''))
        if role is None or cls is None:  # retired meanwhile
            return
        try:
            msg = deserialize_message(data, cls)
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            if role == 'ball':
                p, o = msg.pose.position, msg.pose.orientation
                self._scene.ball(name, stamp, (p.x, p.y, p.z), (o.x, o.y, o.z, o.w))
            elif role == 'velocity':
                self._scene.ball_velocity(name, mb.vector_of(msg.twist.twist.linear))
            elif role == 'landing':
                p = msg.pose.pose.position
                cov = [list(msg.pose.covariance[i * 6:i * 6 + 3]) for i in range(3)]
                self._scene.landing(name, stamp, (p.x, p.y, p.z), cov)
            else:
                points = [(s.pose.position.x, s.pose.position.y, s.pose.position.z)
                          for s in msg.poses[:100000]]
                self._scene.path(name, stamp, role, points)
        except (SceneError, ValueError, TypeError) as exc:  # a malformed message: skip it
            self._refused += 1
            self._refusal = f'{topic}: {exc}'[:200]

    def _scene_step(self, stamp_ns: int) -> None:
        """Feed the scene the newest message of each source and send one update."""
        with self._scene_lock:
            latest, self._latest = self._latest, {}
            removed, self._removed = self._removed, []
        for name in removed:
            self._scene.remove(name)
        for topic in sorted(latest, key=lambda t: t.endswith('odom')):
            self._feed(topic, latest[topic])  # poses before the velocities that use them
        self._scene_channel.log(self._scene.update(stamp_ns), log_time=stamp_ns)
        self._scenes += 1

    def _live(self) -> None:
        period = 1.0 / self.scene_rate
        while not self._stop.wait(period):
            if self._viewers.get(SCENE_TOPIC):
                self._scene_step(time.time_ns())

    # --- the bag's player (its own thread) --------------------------------------------------
    def _play(self) -> None:
        bag, clock = self._bag, self._playhead
        messages, pending = None, None
        last_time = last_scene = 0.0
        while not self._stop.is_set():
            with self._lock:
                seek, self._seek_to = self._seek_to, None
                now = clock.position()
                playing = clock.playing
            if seek is not None:  # the trails and predictions start again from there
                messages, pending = bag.messages(seek), None
                self._scene.clear()
            while playing and messages is not None:
                if pending is None:
                    pending = next(messages, None)
                    if pending is None:
                        messages = None
                        break
                topic, stamp, data = pending
                if stamp > now:
                    break
                pending = None
                channel = self._channels.get(topic)
                if channel is not None:
                    channel.log(data, log_time=stamp)
                    self._forwarded += 1
                if topic in self._roles:
                    with self._scene_lock:
                        self._latest[topic] = data
            wall = time.monotonic()
            if wall - last_time >= TIME_BROADCAST_S:
                self.server.broadcast_time(now)
                last_time = wall
            if self._latest and wall - last_scene >= 1.0 / self.scene_rate:
                self._scene_step(now)
                last_scene = wall
            if playing and clock.ended and messages is None:
                with self._lock:
                    clock.pause()
                    self.server.broadcast_playback_state(self._playback_state('', False))
            self._stop.wait(0.005 if playing else 0.05)

    # --- diagnostics and shutdown -----------------------------------------------------------
    def _diagnose(self) -> None:
        viewers = {c for clients in self._viewers.values() for c in clients}
        values = {
            'url': self.url,
            'viewers': len(viewers),
            'channels': len(self._channels) + 1,
            'subscribed topics': self._subscribed,
            'forwarded': self._forwarded,
            'scene updates': self._scenes,
            'viewer queue overflows': self._overflows.count,
            'topics left out': self._left_out,
            'messages refused by the scene': self._refused,
        }
        level = 'WARN' if self._overflows.count or self._refused else 'OK'
        text = (f'{len(viewers)} viewer(s); {self._overflows.count} viewer queue overflow(s) '
                '(oldest messages dropped)'
                + (f'; last refused: {self._refusal}' if self._refused else ''))
        name = self.get_fully_qualified_name()
        status = mb.diagnostic_status(f'football_ros: {name}', level, text, values,
                                      hardware_id=f'football_ros{name}')
        self._diag_pub.publish(DiagnosticArray(
            header=mb.header(self.get_clock().now().to_msg(), ''), status=[status]))

    def close(self) -> None:
        """Stop the threads (the forwarder destroys its subscriptions) and the server."""
        self._stop.set()
        self._wake.trigger()
        for thread in self._threads:
            thread.join(timeout=2.0)
        self._wake.destroy()
        if self._bag is not None:
            self._bag.close()
        self.server.stop()
        logging.getLogger('foxglove').removeHandler(self._overflows)


def no_delay(port: int) -> int:
    """
    Set TCP_NODELAY on this process's listening TCP sockets on ``port``; return how many.

    The Foxglove SDK's server leaves Nagle's algorithm on for its clients, so a small message
    waits for the client's (delayed, up to 40 ms) acknowledgement of the one before; on Linux
    an accepted connection inherits the option from the listening socket, so setting it there
    before any viewer connects covers every viewer. Finds the sockets by their inodes in
    /proc (0 where there is no /proc).
    """
    inodes = set()
    for table in ('/proc/net/tcp', '/proc/net/tcp6'):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()  # sl local remote state ... inode (field 9)
            if (len(fields) > 9 and fields[3] == '0A'  # LISTEN
                    and int(fields[1].rsplit(':', 1)[1], 16) == port):
                inodes.add(f'socket:[{fields[9]}]')
    done = 0
    try:
        fds = os.listdir('/proc/self/fd')
    except OSError:
        return 0
    for fd in fds:
        try:
            if os.readlink(f'/proc/self/fd/{fd}') not in inodes:
                continue
            sock = socket.socket(fileno=os.dup(int(fd)))  # closing a dup leaves it open
        except OSError:  # the descriptor closed meanwhile
            continue
        with sock:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            done += 1
    return done


def _loopback(host: str) -> bool:
    if host == 'localhost':
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ros_args = argv[argv.index('--ros-args'):] if '--ros-args' in argv else []
    own = argv[: len(argv) - len(ros_args)]
    parser = argparse.ArgumentParser(
        prog='football-ros view',
        description=__doc__.splitlines()[1].replace('``', ''),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog='parameters (--ros-args -p NAME:=VALUE; the options above win):\n'
        + '\n'.join(spec.help_line() for spec in PARAMETERS),
    )
    parser.add_argument('--port', type=int, help='WebSocket port (default 8765; 0 = any)')
    parser.add_argument('--host', help='address to serve on (default 127.0.0.1)')
    parser.add_argument('--bag', help='serve this bag folder instead of the live topics')
    args = parser.parse_args(own)
    return run_node(lambda: ViewNode(args.host, args.port, args.bag), ros_args, 'view')


if __name__ == '__main__':
    raise SystemExit(main())
