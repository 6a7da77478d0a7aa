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
Playing a recorded bag back: its messages in time order and the player's clock; no ROS.

:func:`open_bag` reads a rosbag2 folder (mcap or sqlite3, as ``football-ros record`` writes it)
with rosbags; :class:`PlaybackClock` maps the wall clock to the bag's clock through play,
pause, seek and speed, as a viewer's time controls ask for them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import time
from typing import Callable, Iterator

MIN_SPEED, MAX_SPEED = 0.01, 100.0


class BagError(ValueError):
    """A bag that cannot be served; the message names the file."""


@dataclass(frozen=True)
class BagTopic:
    """One topic of a bag: name, ROS type ('pkg/msg/Type') and its ros2msg definition."""

    name: str
    ros_type: str
    definition: str


class Bag:
    """A readable bag: its topics, time range [ns] and messages from a time on."""

    def __init__(self, path: str | Path) -> None:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import get_typestore, Stores

        self.path = Path(path)
        try:
            self._reader = AnyReader([self.path],
                                     default_typestore=get_typestore(Stores.ROS2_JAZZY))
            self._reader.open()
        except Exception as exc:  # noqa: BLE001 - rosbags raises many types for a bad bag
            raise BagError(f"bag '{str(path)[:200]}': cannot read it ({exc})"[:400]) from None
        self.topics: dict[str, BagTopic] = {}
        for conn in self._reader.connections:
            definition = getattr(conn, 'msgdef', None)
            text = getattr(definition, 'data', '') if definition is not None else ''
            self.topics[conn.topic] = BagTopic(conn.topic, conn.msgtype, text)
        self.start_ns, self.end_ns = int(self._reader.start_time), int(self._reader.end_time)
        if not self.topics or self.end_ns < self.start_ns:
            raise BagError(f"bag '{str(path)[:200]}': no messages")

    def messages(self, start_ns: int) -> Iterator[tuple[str, int, bytes]]:
        """(topic, log time [ns], CDR bytes) of every message at or after ``start_ns``."""
        for conn, stamp, data in self._reader.messages(start=int(start_ns)):
            yield conn.topic, int(stamp), bytes(data)

    def close(self) -> None:
        """Close the reader (idempotent)."""
        self._reader.close()


class PlaybackClock:
    """
    The bag time [ns] a player is at: ``position(wall)`` while playing, fixed while paused.

    Starts paused at ``start_ns``; ``speed`` is a factor of real time in
    [MIN_SPEED, MAX_SPEED]; every seek is clamped to [start_ns, end_ns].
    """

    def __init__(self, start_ns: int, end_ns: int,
                 wall: Callable[[], int] = time.monotonic_ns) -> None:
        self.start_ns, self.end_ns, self._wall = int(start_ns), int(end_ns), wall
        self.speed, self.playing = 1.0, False
        self._anchor_bag, self._anchor_wall = self.start_ns, wall()

    def position(self) -> int:
        """Bag time [ns] now (clamped to the end)."""
        if not self.playing:
            return self._anchor_bag
        moved = (self._wall() - self._anchor_wall) * self.speed
        return min(self.end_ns, self._anchor_bag + int(moved))

    @property
    def ended(self) -> bool:
        """Tell whether the clock has reached the bag's end."""
        return self.position() >= self.end_ns

    def _rebase(self, bag_ns: int) -> None:
        self._anchor_bag = min(max(int(bag_ns), self.start_ns), self.end_ns)
        self._anchor_wall = self._wall()

    def play(self) -> None:
        """Run from the current position (from the start again once ended)."""
        self._rebase(self.start_ns if self.ended else self.position())
        self.playing = True

    def pause(self) -> None:
        """Hold the current position."""
        self._rebase(self.position())
        self.playing = False

    def seek(self, bag_ns: int) -> None:
        """Jump to ``bag_ns`` (clamped to the bag), playing or paused as before."""
        self._rebase(bag_ns)

    def set_speed(self, speed: float) -> None:
        """Set the speed (a factor of real time; clamped to [MIN_SPEED, MAX_SPEED])."""
        if not speed == speed:  # NaN: keep the speed
            return
        self._rebase(self.position())
        self.speed = min(max(float(speed), MIN_SPEED), MAX_SPEED)
