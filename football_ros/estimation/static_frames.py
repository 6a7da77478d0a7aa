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
A tree of static frames (what /tf_static holds), without tf2: fixes from any known frame.

Each transform parent <- child is a rotation (unit quaternion x, y, z, w) and a translation
[m]: a point p_child in the child frame is R p_child + t in the parent frame (tf2's
convention). A child has one parent (a newer transform replaces the older); chains are
composed through the tree, either way. Bounded: at most :data:`MAX_FRAMES` frames.
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.frames import quaternion_to_matrix

MAX_FRAMES = 256
MAX_TRANSLATION = 1e5
"""Largest translation [m] a static transform may claim."""


class StaticFrames:
    """Static transforms by child frame; :meth:`lookup` composes them."""

    def __init__(self) -> None:
        self._parent: dict[str, tuple[str, np.ndarray, np.ndarray]] = {}

    def __len__(self) -> int:
        return len(self._parent)

    def add(self, parent: str, child: str, translation, rotation) -> None:
        """
        Record parent <- child; raise ValueError naming the bad field.

        ``translation`` (3,) [m], ``rotation`` (x, y, z, w) a quaternion (normalised here).
        """
        if not isinstance(parent, str) or not isinstance(child, str) or not parent or not child:
            raise ValueError('frame ids must be non-empty strings')
        if parent == child:
            raise ValueError(f"transform from '{child[:40]}' to itself")
        t = np.asarray(translation, dtype=float).reshape(-1)
        q = np.asarray(rotation, dtype=float).reshape(-1)
        if t.size != 3 or not np.all(np.isfinite(t)) or np.any(np.abs(t) > MAX_TRANSLATION):
            raise ValueError(f"translation of '{child[:40]}' must be 3 finite numbers [m]")
        norm = float(np.linalg.norm(q)) if q.size == 4 else math.nan
        if not (math.isfinite(norm) and 0.5 < norm < 2.0):
            raise ValueError(f"rotation of '{child[:40]}' must be a unit quaternion")
        if child not in self._parent and len(self._parent) >= MAX_FRAMES:
            raise ValueError(f'more than {MAX_FRAMES} static frames')
        self._parent[child] = (parent, quaternion_to_matrix(q / norm), t)

    def _to_root(self, frame: str) -> tuple[list[str], np.ndarray, np.ndarray]:
        """Frames from ``frame`` up to its root, and the root <- frame rotation, translation."""
        chain, R, t = [frame], np.eye(3), np.zeros(3)
        while chain[-1] in self._parent and len(chain) <= MAX_FRAMES:
            parent, Rp, tp = self._parent[chain[-1]]
            R, t = Rp @ R, Rp @ t + tp
            if parent in chain:  # a loop: no root
                return chain, R, t
            chain.append(parent)
        return chain, R, t

    def lookup(self, target: str, source: str) -> tuple[np.ndarray, np.ndarray] | None:
        """Return (R, t): p_target = R p_source + t, or None if the frames are not connected."""
        if target == source:
            return np.eye(3), np.zeros(3)
        chain_s, Rs, ts = self._to_root(source)
        chain_t, Rt, tt = self._to_root(target)
        if chain_s[-1] != chain_t[-1] or chain_s[-1] in self._parent:
            return None
        # target <- source = (root <- target)^-1 (root <- source)
        return Rt.T @ Rs, Rt.T @ (ts - tt)
