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
A camera rig file: calibrated cameras, their poses in ``field`` and how they detect the ball.

YAML (the strict language of :mod:`football_ros.strict_yaml`), one mapping ``cameras`` of
camera name -> settings::

    cameras:
      left:
        width: 1920                 # CameraInfo fields [px]
        height: 1080
        distortion_model: plumb_bob # or rational_polynomial
        D: [k1, k2, p1, p2, k3]     # [] = no distortion
        K: [fx, 0, cx, 0, fy, cy, 0, 0, 1]
        R: [...]                    # 9 numbers, default identity
        P: [...]                    # 12 numbers, default [K | 0]
        position: [x, y, z]         # the optical centre in field [m]
        look_at: [x, y, z]          # a point on the optical axis [m], image rows level ...
        # orientation: [qx, qy, qz, qw]  # ... or the optical frame's attitude in field
        frame_id: left_optical      # default <name>_optical
        rate: 60                    # frames per second [Hz]
        phase: 0.0                  # first exposure's offset into the period [s]
        stamp_jitter: 0.0           # 1-sigma error of the exposure stamps [s]
        latency: 0.03               # exposure to delivery [s]
        pixel_noise: 1.0            # 1-sigma per axis of the centre and the box sides [px]
        dropout: 0.0                # probability a visible ball is missed
        outlier_rate: 0.0           # probability a detection lands anywhere in the image
        seed: 0                     # default: the camera's index in the file

Every field is checked; an error names the file, the camera and the field. The optical frame
is ROS's: z forward, x right, y down.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import numpy as np

from .camera import Camera, DISTORTION_MODELS
from ..physics.frames import quaternion_to_matrix, UP
from ..strict_yaml import brief, load_strict

MAX_BYTES = 1 << 20
"""Largest rig file read [bytes]."""
MAX_CAMERAS = 32
LIMITS = {
    'rate': (0.1, 1000.0),
    'phase': (0.0, 10.0),
    'stamp_jitter': (0.0, 1.0),
    'latency': (0.0, 5.0),
    'pixel_noise': (0.0, 100.0),
    'dropout': (0.0, 1.0),
    'outlier_rate': (0.0, 1.0),
}
"""Ranges of a camera's detection settings (units in the module docstring)."""
REQUIRED = ('width', 'height', 'K', 'position', 'rate')
FIELDS = set(REQUIRED) | set(LIMITS) | {
    'distortion_model', 'D', 'R', 'P', 'look_at', 'orientation', 'frame_id', 'seed',
}


@dataclass(frozen=True)
class RigCamera:
    """One camera of a rig: its name, optical ``frame_id``, model and detection settings."""

    name: str
    frame_id: str
    camera: Camera
    rate: float
    phase: float = 0.0
    stamp_jitter: float = 0.0
    latency: float = 0.0
    pixel_noise: float = 1.0
    dropout: float = 0.0
    outlier_rate: float = 0.0
    seed: int = 0


def look_at_rotation(position, target) -> np.ndarray:
    """Optical frame (columns: x right, y down, z forward) from ``position`` toward ``target``."""
    z = np.asarray(target, dtype=float) - np.asarray(position, dtype=float)
    norm = np.linalg.norm(z)
    if not norm > 1e-9:
        raise ValueError('look_at must differ from position')
    z = z / norm
    x = np.cross(z, UP)
    if not np.linalg.norm(x) > 1e-6:
        raise ValueError(
            'look_at must not be straight above or below position (give orientation)'
        )
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _numbers(where: str, value, count: int | tuple[int, ...]) -> np.ndarray:
    counts = (count,) if isinstance(count, int) else count
    if not isinstance(value, list) or len(value) not in counts or not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value
    ):
        want = ' or '.join(str(c) for c in counts)
        raise ValueError(f'{where} must be a list of {want} finite numbers, got {brief(value)}')
    return np.array(value, dtype=float)


def _camera(name: str, index: int, spec) -> RigCamera:
    where = f'camera {name!r}'
    if not isinstance(spec, dict):
        raise ValueError(f'{where} must be a mapping of its settings, got {brief(spec)}')
    unknown = sorted(set(spec) - FIELDS)
    if unknown:
        raise ValueError(f'{where}: unknown field {brief(unknown[0])} (fields: {sorted(FIELDS)})')
    for key in REQUIRED:
        if key not in spec:
            raise ValueError(f"{where}: field '{key}' is missing")
    if ('look_at' in spec) == ('orientation' in spec):
        raise ValueError(f"{where}: give exactly one of 'look_at' and 'orientation'")
    position = _numbers(f"{where} field 'position'", spec['position'], 3)
    try:
        if 'look_at' in spec:
            rotation = look_at_rotation(
                position, _numbers(f"{where} field 'look_at'", spec['look_at'], 3)
            )
        else:
            q = _numbers(f"{where} field 'orientation'", spec['orientation'], 4)
            if abs(np.linalg.norm(q) - 1.0) > 1e-3:
                raise ValueError('orientation must be a unit quaternion (x, y, z, w)')
            rotation = quaternion_to_matrix(q / np.linalg.norm(q))
    except ValueError as exc:
        raise ValueError(f'{where}: {exc}') from None
    model = spec.get('distortion_model', 'plumb_bob')
    if model not in DISTORTION_MODELS:
        raise ValueError(
            f"{where} field 'distortion_model' must be one of {sorted(DISTORTION_MODELS)}, "
            f'got {brief(model)}'
        )
    arrays = {
        'K': _numbers(f"{where} field 'K'", spec['K'], 9),
        'D': _numbers(f"{where} field 'D'", spec.get('D', []), (0, DISTORTION_MODELS[model])),
        'R': _numbers(f"{where} field 'R'", spec.get('R', [1, 0, 0, 0, 1, 0, 0, 0, 1]), 9),
    }
    if 'P' in spec:
        arrays['P'] = _numbers(f"{where} field 'P'", spec['P'], 12)
    try:
        camera = Camera(
            spec['width'], spec['height'], distortion_model=model, rotation=rotation,
            position=position, **arrays,
        )
    except ValueError as exc:
        raise ValueError(f'{where}: {exc}') from None
    numbers = {}
    for key, (lo, hi) in LIMITS.items():
        value = spec.get(key, RigCamera.__dataclass_fields__[key].default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            math.isfinite(value) and lo <= value <= hi
        ):
            raise ValueError(
                f"{where} field '{key}' must be a number in [{lo:g}, {hi:g}], got {brief(value)}"
            )
        numbers[key] = float(value)
    frame_id = spec.get('frame_id', f'{name}_optical')
    if not isinstance(frame_id, str) or not _identifier(frame_id):
        raise ValueError(
            f"{where} field 'frame_id' must be letters, digits and _ (not starting with a "
            f'digit), got {brief(frame_id)}'
        )
    seed = spec.get('seed', index)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise ValueError(f"{where} field 'seed' must be a non-negative integer, got {brief(seed)}")
    return RigCamera(name, frame_id, camera, seed=seed, **numbers)


def _identifier(text: str) -> bool:
    return 0 < len(text) <= 64 and text.replace('_', 'a').isalnum() and text.isascii() and not (
        text[0].isdigit()
    )


def parse_rig(text: str, source: str = 'rig') -> tuple[RigCamera, ...]:
    """Read a rig from YAML text (module docstring); ValueError naming ``source`` and field."""
    try:
        data = load_strict(text)
        if not isinstance(data, dict) or set(data) != {'cameras'}:
            raise ValueError("a rig is a mapping with the one key 'cameras'")
        cameras = data['cameras']
        if not isinstance(cameras, dict) or not 1 <= len(cameras) <= MAX_CAMERAS:
            raise ValueError(
                f"'cameras' must map 1 to {MAX_CAMERAS} camera names to their settings"
            )
        rig = []
        for index, (name, spec) in enumerate(cameras.items()):
            if not _identifier(name):
                raise ValueError(
                    f'camera name {brief(name)} must be letters, digits and _ (not starting '
                    'with a digit; it names topics)'
                )
            rig.append(_camera(name, index, spec))
        frames = [c.frame_id for c in rig]
        if len(set(frames)) != len(frames):
            raise ValueError('two cameras have the same frame_id')
        return tuple(rig)
    except ValueError as exc:
        raise ValueError(f'{source}: {exc}') from None


def load_rig(path: str | Path) -> tuple[RigCamera, ...]:
    """Read a rig file (at most :data:`MAX_BYTES`); ValueError naming the file and field."""
    path = Path(path)
    try:
        with open(path, 'rb') as handle:
            raw = handle.read(MAX_BYTES + 1)
    except OSError as exc:
        raise ValueError(f'{path}: cannot read the rig file ({exc.strerror})') from None
    if len(raw) > MAX_BYTES:
        raise ValueError(f'{path}: a rig file may hold at most {MAX_BYTES} bytes')
    try:
        text = raw.decode('utf-8')
    except UnicodeDecodeError:
        raise ValueError(f'{path}: a rig file must be UTF-8 text') from None
    return parse_rig(text, str(path))
