"""Release requests (text in) and flight hand-offs (release node -> simulator), no ROS needed.

A request is a YAML or JSON mapping of the release keys (``Release.FIELDS``) plus ``id``.
Parsing is safe (``yaml.safe_load``, no aliases, bounded size); every failure raises
:class:`RequestError` with a one-sentence reason and the best id that could be recovered.

A hand-off is the JSON the release node sends the simulator: the full rigid-body initial state
in ``field`` plus ball, overrides, model and moment, so requests given as text or as an
Odometry take one path.
"""

from __future__ import annotations

import itertools
import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

from .physics import BallPreset, Flight, InitialState, Release, ReleaseError, get_preset
from .physics.aero import AeroModel
from .physics.release import MODELS, MOMENT_CURVES

MAX_REQUEST_BYTES = 65536
MAX_ID_LENGTH = 128
_counter = itertools.count(1)


class RequestError(ValueError):
    """A rejected request: ``request_id`` (recovered or made up) and a one-sentence reason."""

    def __init__(self, request_id: str, reason: str) -> None:
        super().__init__(reason)
        self.request_id = request_id


def made_up_id(prefix: str = "req") -> str:
    """A fresh id for a request that brought none: ``req-<n>``."""
    return f"{prefix}-{next(_counter)}"


def brief(value: Any, limit: int = 60) -> str:
    """repr of a value cut to ``limit`` characters, for error messages."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _check_id(raw: Any) -> str:
    if isinstance(raw, bool) or not isinstance(raw, (str, int)):
        raise ValueError(f"'id' must be a string or an integer, got {brief(raw)}")
    text = str(raw)
    if not text or len(text) > MAX_ID_LENGTH or not text.isprintable():
        raise ValueError(f"'id' must be 1 to {MAX_ID_LENGTH} printable characters")
    return text


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads YAML 1.2 / JSON exponents without a dot (``1e9``) as floats."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                |[-+]?\.(?:inf|Inf|INF)
                |\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."))


def _load_mapping(text: str) -> dict:
    """Parse YAML/JSON text into a dict; aliases, non-mappings and bad syntax raise ValueError."""
    try:
        for event in yaml.parse(text, Loader=_Loader):
            if isinstance(event, yaml.AliasEvent):
                raise ValueError("YAML aliases are not accepted")
        data = yaml.load(text, Loader=_Loader)  # a SafeLoader: plain data only
    except yaml.YAMLError as exc:
        where = getattr(exc, "problem_mark", None)
        at = f" at line {where.line + 1}, column {where.column + 1}" if where else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise ValueError(f"malformed YAML/JSON{at}: {problem}") from None
    except RecursionError:
        raise ValueError("malformed YAML/JSON: nested too deeply") from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ValueError(f"the request must be a mapping of release keys, got {type(data).__name__}")
    if not all(isinstance(k, str) for k in data):
        raise ValueError("every key of the request must be a string")
    return data


def parse_release_request(text: str, max_bytes: int = MAX_REQUEST_BYTES) -> tuple[str, Release]:
    """Parse a release request; returns (id, Release) or raises RequestError."""
    if not isinstance(text, str):
        raise RequestError(made_up_id(), "the request must be text")
    size = len(text.encode("utf-8", errors="replace"))
    if size > max_bytes:
        raise RequestError(made_up_id(), f"the request is {size} bytes, more than the {max_bytes} accepted")
    try:
        data = _load_mapping(text)
    except ValueError as exc:
        raise RequestError(made_up_id(), str(exc)) from None
    try:
        request_id = _check_id(data.pop("id")) if "id" in data else made_up_id()
    except ValueError as exc:
        raise RequestError(made_up_id(), str(exc)) from None
    try:
        return request_id, Release.from_mapping(data)
    except ReleaseError as exc:
        raise RequestError(request_id, str(exc)) from None
    except (TypeError, ValueError) as exc:  # e.g. a wrongly typed ball_params entry
        raise RequestError(request_id, f"invalid release: {exc}") from None


@dataclass(frozen=True)
class FlightOrder:
    """What the simulator needs to fly a ball: id, ball, model, moment and initial state."""

    request_id: str
    ball_name: str
    ball_params: dict
    model: str
    moment: str
    initial: InitialState
    aero: dict = field(default_factory=dict)

    def ball(self) -> BallPreset:
        return get_preset(self.ball_name, self.ball_params)

    def flight(self, step: float, model: str | None = None) -> Flight:
        """The Flight this order means (``model`` overrides the ordered one)."""
        model = model or self.model
        aero = AeroModel.from_mapping(self.aero) if model == "full" else None
        return Flight(self.ball(), self.initial, model, self.moment, step, aero)

    @staticmethod
    def from_release(request_id: str, release: Release) -> "FlightOrder":
        return FlightOrder(request_id, release.ball, dict(release.ball_params), release.model,
                           release.moment, release.initial_state(), dict(release.aero))

    def to_json(self) -> str:
        st = self.initial
        return json.dumps({
            "id": self.request_id, "ball": self.ball_name, "ball_params": self.ball_params,
            "model": self.model, "moment": self.moment, "aero": self.aero,
            "position": st.position.tolist(), "velocity": st.velocity.tolist(),
            "orientation": st.attitude.tolist(), "angular_velocity": st.angular_velocity().tolist(),
        })

    @staticmethod
    def from_json(text: str) -> "FlightOrder":
        """Inverse of :meth:`to_json`; validates everything again (raises ValueError)."""
        try:
            data = json.loads(text)
            if not isinstance(data, dict):
                raise ValueError("a flight order must be a JSON object")
            if data.get("model") not in MODELS or data.get("moment") not in MOMENT_CURVES:
                raise ValueError(f"bad model/moment {brief(data.get('model'))}/{brief(data.get('moment'))}")
            ball_params = data.get("ball_params") or {}
            if not isinstance(ball_params, dict):
                raise ValueError("ball_params must be a mapping")
            get_preset(data.get("ball"), ball_params)
            aero = data.get("aero") or {}
            AeroModel.from_mapping(aero)
            initial = InitialState.from_rigid_body(data["position"], data["velocity"],
                                                   data["orientation"], data["angular_velocity"])
            return FlightOrder(_check_id(data["id"]), data["ball"], ball_params, data["model"],
                               data["moment"], initial, aero)
        except (KeyError, TypeError, AttributeError, json.JSONDecodeError) as exc:
            raise ValueError(f"malformed flight order: {brief(exc)}") from None


def flight_summary(times: np.ndarray, positions: np.ndarray, landed: bool) -> dict[str, float]:
    """time_of_flight [s], range [m] (horizontal distance from the release), apex height [m]."""
    horizontal = positions[-1, :2] - positions[0, :2]
    return {"time_of_flight": float(times[-1]) if landed else math.nan,
            "range": float(np.hypot(*horizontal)) if landed else math.nan,
            "apex_height": float(np.max(positions[:, 2]))}
