"""Each edge's stable region for planning, computed once per part.

Procedure STABLE is a closed form; the exact region (:mod:`mechanics.exact_region`) costs about a
tenth of a second of certified linear programmes per edge. It depends only on the part, the edge,
the friction and the pusher's width, so it is kept in memory for the process and on disk across runs:
a JSON file per region under ``$STABLEPUSH_CACHE`` (default ``$XDG_CACHE_HOME/stablepush`` or
``~/.cache/stablepush``), named by a hash of everything it depends on, written atomically. A cache
that cannot be read or written is ignored: the region is then computed again, never guessed.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import shapely

from mechanics import ExactRegion, Slider, StableRegion, exact_region, stable_region

from .fields import SceneError
from .plan_file import write_atomic

__all__ = ["cache_folder", "edge_region", "is_cached"]

#: Bump when the exact region's construction changes, so old cache files are not used.
#: 3: the support LPs by a batched simplex (its duals can differ where the LP is degenerate).
_VERSION = 3

_memory: dict[str, ExactRegion] = {}


def cache_folder() -> Path:
    """Where exact regions are kept between runs."""
    if os.environ.get("STABLEPUSH_CACHE"):
        return Path(os.environ["STABLEPUSH_CACHE"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "stablepush"


def _key(slider: Slider, edge: int, mu: float, width: float | None, cf_radius: float) -> str:
    spec = {"version": _VERSION, "vertices": slider.vertices.tolist(), "cf": slider.cf.tolist(),
            "edge": int(edge), "mu": float(mu), "width": None if width is None else float(width),
            "cf_radius": float(cf_radius)}
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:32]


def _path(key: str) -> Path:
    return cache_folder() / f"exact-{key}.json"


def _read(path: Path, stable: StableRegion, cf_radius: float) -> ExactRegion | None:
    try:
        data = json.loads(path.read_text())
        polygon = shapely.Polygon(np.asarray(data["polygon"], dtype=float))
        centre = np.asarray(data["centre"], dtype=float)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not polygon.is_valid or polygon.area <= 0 or centre.shape != (2,):
        return None
    return ExactRegion(stable, polygon, centre, cf_radius)


def is_cached(slider: Slider, edge: int, mu: float, width: float | None = None, method: str = "exact",
              cf_radius: float = 0.0) -> bool:
    """Whether :func:`edge_region` would answer without computing an exact region (a file that
    turns out unreadable is computed all the same)."""
    if method == "stable" or stable_region(slider, edge, mu, width).is_empty:
        return True
    key = _key(slider, edge, mu, width, cf_radius)
    return key in _memory or _path(key).is_file()


def edge_region(slider: Slider, edge: int, mu: float, width: float | None = None, method: str = "exact",
                cf_radius: float = 0.0, deadline: float | None = None) -> StableRegion | ExactRegion:
    """The ``method`` (``'stable'`` or ``'exact'``) stable region of ``edge``, cached as above;
    ``cf_radius`` (exact only) makes it hold for every CF within that distance of the slider's.

    Raises
    ------
    SceneError
        For ``method='stable'`` with ``cf_radius > 0``: procedure STABLE assumes a known CF.
    mechanics.DeadlineExceeded
        When an exact region must be computed and is not done by ``deadline`` (a
        :func:`time.perf_counter` time); nothing is cached then.
    """
    if method == "stable" and cf_radius > 0:
        raise SceneError("planner.regions", "procedure STABLE assumes a known CF; slider.cf_uncertainty needs "
                                            "the exact regions")
    stable = stable_region(slider, edge, mu, width)
    if method == "stable" or stable.is_empty:
        return stable
    key = _key(slider, edge, mu, width, cf_radius)
    if key in _memory:
        return _memory[key]
    path = _path(key)
    region = _read(path, stable, cf_radius)
    if region is None:
        region = exact_region(slider, edge, mu, width, cf_radius=cf_radius, deadline=deadline)
        polygon, centre = region.section()
        if isinstance(polygon, shapely.Polygon) and polygon.area > 0:  # a degenerate one is cheap: not stored
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                write_atomic(path, json.dumps({"polygon": np.asarray(polygon.exterior.coords).tolist(),
                                               "centre": centre.tolist()}))
            except OSError:
                pass  # a read-only home: compute again next time
    _memory[key] = region
    return region
