"""Reading a scene file of either kind: one part (:mod:`.scene`) or several (:mod:`.parts`).

A mapping with ``parts:`` is a multi-part scene; any other, a one-part scene.

>>> type(load_scene("scenes/battery.yaml")).__name__, type(load_scene("scenes/parts/swap.yaml")).__name__
('Scene', 'PartsScene')
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from . import scene
from .parts import PartsScene, parse_parts_scene

__all__ = ["load_scene", "parse_scene"]


def parse_scene(data: Any, default_name: str = "scene", path: str | None = None) -> scene.Scene | PartsScene:
    """Validate a scene given as the parsed YAML mapping; the files it names are relative to the
    folder of ``path`` (the working folder if None).

    Raises
    ------
    SceneError
        Naming the field at fault.
    """
    if isinstance(data, dict) and "parts" in data:
        return parse_parts_scene(data, default_name, path)
    return scene.parse_scene(data, default_name, path)


def load_scene(path: str | Path) -> scene.Scene | PartsScene:
    """Read and validate a YAML scene file of either kind.

    Raises
    ------
    SceneError
        If the file cannot be read or any field is missing, unknown or invalid.
    """
    return scene.load_scene(path, parse_scene)
