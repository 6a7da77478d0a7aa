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
The nodes' parameter tables, gathered: msg_docs/parameters.md is written from them.

``python -m football_ros.nodes.reference > msg_docs/parameters.md`` regenerates the page (a test
fails when it is stale).
"""

from __future__ import annotations

import importlib
import sys
from typing import Sequence

from rclpy.node import Node

from .params import markdown, ParamSpec, with_guards
from ..programs import NODES


def node_class(module_name: str) -> type[Node]:
    """Return the Node subclass a node module defines (the one its ``main`` runs)."""
    module = importlib.import_module(module_name)
    classes = [
        v
        for v in vars(module).values()
        if isinstance(v, type) and issubclass(v, Node) and v.__module__ == module.__name__
    ]
    if len(classes) != 1:
        raise LookupError(f'{module_name} defines {len(classes)} Node classes, expected 1')
    return classes[0]


def node_tables() -> dict[str, Sequence[ParamSpec]]:
    """Return {executable name: its node's parameter table, guards first} for every node."""
    return {name: with_guards(node_class(module).PARAMETERS) for name, module in NODES.items()}


def main() -> int:
    sys.stdout.write(markdown(node_tables()))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
