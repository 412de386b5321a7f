"""Scene files: the part, the pusher, the table and the task, read from YAML and validated.

Every problem is reported as a :class:`~planner.fields.SceneError` naming the offending field, so the command
line can print one line and exit 1. The format is documented in the README.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import yaml

from mechanics import Slider

from .bodies import slider_at
from .fields import SceneError, integer, keys, number, vector

__all__ = ["DEFAULT_PLANNER", "DEFAULT_REGIONS", "DEFAULT_SWITCH_COST", "DEFAULT_TRANSIT", "REGIONS", "TRANSITS",
           "check_switch_cost", "check_transit", "MAX_SEED", "MAX_TIME_LIMIT", "SceneError", "Pusher", "PlannerOptions", "Scene",
           "check_regions", "check_seed", "check_time_limit", "load_scene", "parse_scene", "PLANNERS"]

PLANNERS = ("rrt", "kpiece", "est")
#: How each edge's stable pushes are found: procedure STABLE, or the exact region that contains it.
REGIONS = ("stable", "exact")
#: Both are sound (mechanics.exact_region); the exact region is the larger.
DEFAULT_REGIONS = "exact"
#: How the pusher may get from one edge to another: on the table, lifted over it (an arm; table
#: moves are allowed too), or not at all (one edge per plan).
TRANSITS = ("plane", "lift", "none")
DEFAULT_TRANSIT = "plane"
#: What a switch of edge costs, in metres of the centre of friction's path: a plan that switches
#: must be shorter than one that does not by more than this for each switch (Lynch & Mason 1996,
#: §4, cost per contact change).
DEFAULT_SWITCH_COST = 0.25
#: The planner used when neither the scene nor the caller names one (chosen by planner.bench).
DEFAULT_PLANNER = "rrt"
#: Seeds are OMPL's ``std::uint_fast32_t``: 32 bits is the most every platform takes.
MAX_SEED = 2**32 - 1
#: One day. OMPL's deadline (now + limit) overflows for limits of some years and then ends the
#: search at once, so a huge or infinite limit would report failure without having searched.
MAX_TIME_LIMIT = 86400.0
#: Longest scene name in bytes: it names files, which most file systems cap at 255 bytes.
_MAX_NAME_BYTES = 200


@dataclass(frozen=True)
class Pusher:
    """The flat pusher. ``mu`` is the friction the plan relies on: the scene's value, or the low
    end of its interval ``[mu, mu_high]`` (sticking at the lowest friction implies sticking at
    any higher one, :func:`mechanics.exact_region`)."""

    width: float
    depth: float
    mu: float
    edges: tuple[int, ...]  # the edges that may be pushed
    mu_high: float | None = None  # top of the friction interval, if one was given
    transit: str = DEFAULT_TRANSIT  # how it moves between edges (TRANSITS)


@dataclass(frozen=True)
class PlannerOptions:
    name: str = DEFAULT_PLANNER
    time_limit: float = 10.0
    seed: int = 1
    regions: str = DEFAULT_REGIONS
    switch_cost: float = DEFAULT_SWITCH_COST


@dataclass(frozen=True)
class Scene:
    """A validated scene. Poses are ``(x, y, theta)`` in metres and **radians**."""

    name: str
    slider: Slider
    pusher: Pusher
    obstacles: tuple[shapely.Polygon, ...]
    workspace: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
    start: np.ndarray
    goal: np.ndarray
    tolerance_position: float = 0.01
    tolerance_angle: float = math.radians(2.0)
    planner: PlannerOptions = field(default_factory=PlannerOptions)
    path: str | None = None  # the file it was read from
    cf_uncertainty: float = 0.0  # radius of the disk about slider.cf holding the true CF (metres)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a YAML scene file.

    Raises
    ------
    SceneError
        If the file cannot be read or any field is missing, unknown or invalid.
    """
    path = Path(path)
    return parse_scene(_read_yaml(path), default_name=path.stem, path=str(path))


def _read_yaml(path: Path) -> Any:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise SceneError("scene", f"cannot read {str(path)!r}: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise SceneError("scene", f"{str(path)!r} is not UTF-8 text (bad byte at offset {err.start})") from None
    try:
        return yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or " ".join(str(err).split())  # some messages span two lines
        raise SceneError("scene", f"malformed YAML{where}: {problem}") from None
    except RecursionError:
        raise SceneError("scene", "malformed YAML: nested too deeply") from None
    except ValueError as err:  # PyYAML lets Python's own limits through, e.g. on ints of over 4300 digits
        raise SceneError("scene", f"malformed YAML: {err}") from None


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader that also reads ``1e-3`` as a number: YAML 1.1 wants a dot (``1.0e-3``)
    and PyYAML would otherwise hand the scene the string ``"1e-3"``."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789"))


def _points(value: Any, name: str) -> np.ndarray:
    if not isinstance(value, (list, tuple)):
        raise SceneError(name, "must be a list of [x, y] points")
    if len(value) < 3:
        raise SceneError(name, f"needs at least 3 vertices, got {len(value)}")
    return np.array([vector(p, f"{name}[{i}]", 2) for i, p in enumerate(value)])


def _polygon(value: Any, name: str) -> shapely.Polygon:
    return _simple_polygon(_points(value, name), name)


def _simple_polygon(pts: np.ndarray, name: str) -> shapely.Polygon:
    # Area first: the ring of collinear points doubles back on itself, and "self-intersecting"
    # would send the reader looking for a crossing. The threshold is the one Slider uses.
    if shapely.MultiPoint(pts).convex_hull.area <= 1e-12 * max(1.0, float(np.ptp(pts)) ** 2):
        raise SceneError(name, "polygon has zero area (its vertices are collinear or too close together)")
    if not shapely.LinearRing(pts).is_simple:
        raise SceneError(name, "polygon is self-intersecting")
    return shapely.Polygon(pts)


def _obstacle(value: Any, name: str) -> shapely.Polygon:
    if not isinstance(value, dict) or len(value) != 1 or next(iter(value)) not in ("polygon", "box"):
        raise SceneError(name, "must be {polygon: [[x, y], ...]} or {box: {center, size, angle}}")
    if "polygon" in value:
        return _polygon(value["polygon"], f"{name}.polygon")
    box = keys(value["box"], f"{name}.box", ("center", "size"), ("angle",))
    cx, cy = vector(box["center"], f"{name}.box.center", 2)
    w, h = vector(box["size"], f"{name}.box.size", 2)
    if not (w > 0 and h > 0):
        raise SceneError(f"{name}.box.size", f"must be positive, got {[w, h]}")
    angle = math.radians(number(box.get("angle", 0.0), f"{name}.box.angle"))
    corners = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    return shapely.Polygon(corners @ rot.T + [cx, cy])


def _slider(value: Any) -> Slider:
    spec = keys(value, "slider", ("vertices",), ("cf", "cf_uncertainty"))
    vertices = _points(spec["vertices"], "slider.vertices")
    _simple_polygon(vertices, "slider.vertices")
    # A repeated vertex makes an edge of no length, with no normal to push along; shapely accepts it.
    repeated = np.flatnonzero(np.all(vertices == np.roll(vertices, -1, axis=0), axis=1))
    if len(repeated):
        k = int(repeated[0])
        raise SceneError("slider.vertices", f"vertices {k} and {(k + 1) % len(vertices)} coincide, so edge {k} "
                                            "has no length (do not repeat the first vertex at the end)")
    try:
        Slider(vertices)
    except ValueError as err:
        raise SceneError("slider.vertices", str(err)) from None
    if "cf" not in spec:
        return Slider(vertices)
    cf = vector(spec["cf"], "slider.cf", 2)  # outside the try: a SceneError is a ValueError too
    try:
        return Slider(vertices, cf)
    except ValueError as err:
        raise SceneError("slider.cf", str(err)) from None


def _pusher(value: Any, slider: Slider) -> Pusher:
    spec = keys(value, "pusher", ("width", "depth", "mu"), ("edges", "transit"))
    width = number(spec["width"], "pusher.width", positive=True)
    depth = number(spec["depth"], "pusher.depth", positive=True)
    mu, mu_high = _friction(spec["mu"])
    transit = check_transit(spec.get("transit", DEFAULT_TRANSIT), "pusher.transit")
    if "edges" not in spec:
        return Pusher(width, depth, mu, slider.pushable_edges, mu_high, transit)
    listed = spec["edges"]
    if not isinstance(listed, (list, tuple)) or not listed:
        raise SceneError("pusher.edges", "must be a non-empty list of edge indices")
    edges = []
    for i, e in enumerate(listed):
        e = integer(e, f"pusher.edges[{i}]")
        if not 0 <= e < slider.n:
            raise SceneError("pusher.edges", f"edge {e} does not exist (the part has edges 0..{slider.n - 1})")
        if not slider.is_pushable(e):
            raise SceneError("pusher.edges", f"edge {e} is not on the convex hull, so a flat pusher cannot push it")
        if e in edges:
            raise SceneError("pusher.edges", f"edge {e} is listed twice")
        edges.append(e)
    return Pusher(width, depth, mu, tuple(edges), mu_high, transit)


def _friction(value: Any) -> tuple[float, float | None]:
    """``pusher.mu``: a number > 0, or an interval ``[low, high]`` with ``0 < low <= high``."""
    if not isinstance(value, (list, tuple)):
        return number(value, "pusher.mu", positive=True), None
    low, high = vector(value, "pusher.mu", 2)
    if not 0 < low <= high:
        raise SceneError("pusher.mu", f"an interval must be [low, high] with 0 < low <= high, got {list(value)}")
    return float(low), float(high)


def _pose(value: Any, name: str, slider: Slider, obstacles, workspace) -> np.ndarray:
    x, y, theta = vector(value, name, 3)
    pose = np.array([x, y, math.radians(theta)])
    body = slider_at(slider.polygon, pose)
    if not shapely.box(*workspace).contains(body):
        raise SceneError(name, "the part is not inside the workspace")
    for k, obstacle in enumerate(obstacles):
        if body.intersects(obstacle):
            raise SceneError(name, f"the part collides with obstacle {k}")
    return pose


def parse_scene(data: Any, default_name: str = "scene", path: str | None = None) -> Scene:
    """Validate a scene given as the parsed YAML mapping (see :func:`load_scene`)."""
    spec = keys(data, "scene", ("slider", "pusher", "workspace", "start", "goal"),
                 ("name", "obstacles", "tolerance", "planner"))
    name = _name(spec.get("name", default_name))
    slider = _slider(spec["slider"])
    cf_uncertainty = _cf_uncertainty(spec["slider"], slider)
    pusher = _pusher(spec["pusher"], slider)
    obstacles_spec = [] if spec.get("obstacles") is None else spec["obstacles"]  # None: a bare "obstacles:"
    if not isinstance(obstacles_spec, list):
        raise SceneError("obstacles", "must be a list")
    obstacles = tuple(_obstacle(o, f"obstacles[{k}]") for k, o in enumerate(obstacles_spec))
    ws = keys(spec["workspace"], "workspace", ("min", "max"))
    lo, hi = vector(ws["min"], "workspace.min", 2), vector(ws["max"], "workspace.max", 2)
    if not np.all(hi > lo):
        raise SceneError("workspace", f"is empty or inverted: max {hi.tolist()} must exceed min {lo.tolist()}")
    workspace = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    start = _pose(spec["start"], "start", slider, obstacles, workspace)
    goal = _pose(spec["goal"], "goal", slider, obstacles, workspace)
    tol = keys(spec.get("tolerance", {}), "tolerance", (), ("position", "angle"))
    tol_pos = number(tol.get("position", 0.01), "tolerance.position", positive=True)
    tol_ang = math.radians(number(tol.get("angle", 2.0), "tolerance.angle", positive=True))
    opts = keys(spec.get("planner", {}), "planner", (), ("name", "time_limit", "seed", "regions", "switch_cost"))
    planner = PlannerOptions(
        name=_one_of(opts.get("name", DEFAULT_PLANNER), PLANNERS, "planner.name"),
        time_limit=check_time_limit(opts.get("time_limit", 10.0), "planner.time_limit"),
        seed=check_seed(opts.get("seed", 1), "planner.seed"),
        regions=check_regions(opts.get("regions", DEFAULT_REGIONS), "planner.regions"),
        switch_cost=check_switch_cost(opts.get("switch_cost", DEFAULT_SWITCH_COST), "planner.switch_cost"),
    )
    return Scene(name, slider, pusher, obstacles, workspace, start, goal, tol_pos, tol_ang, planner, path,
                 cf_uncertainty)


def _cf_uncertainty(spec: dict, slider: Slider) -> float:
    """``slider.cf_uncertainty``: the radius (>= 0, less than the part's radius) of the disk about
    the CF that holds the true CF."""
    radius = number(spec.get("cf_uncertainty", 0.0), "slider.cf_uncertainty")
    if not 0 <= radius < slider.radius:
        raise SceneError("slider.cf_uncertainty", f"must be >= 0 and less than the part's radius "
                                                  f"{slider.radius:.4g}, got {radius!r}")
    return radius


def _name(value: Any) -> str:
    # The name names the output files, so it must make a plain file name.
    if not isinstance(value, str) or not value or not value.isprintable() or any(c in value for c in "/\\"):
        raise SceneError("name", f"must be a plain non-empty string, got {value!r}")
    if len(value.encode()) > _MAX_NAME_BYTES:
        raise SceneError("name", f"must be at most {_MAX_NAME_BYTES} bytes long, got {len(value.encode())}")
    return value


def _one_of(value: Any, choices: tuple[str, ...], name: str) -> str:
    if value not in choices:
        raise SceneError(name, f"must be one of {', '.join(choices)}, got {value!r}")
    return value


def check_regions(value: Any, name: str) -> str:
    """``value`` as a region method (:data:`REGIONS`); else a :class:`SceneError` naming ``name``."""
    return _one_of(value, REGIONS, name)


def check_transit(value: Any, name: str) -> str:
    """``value`` as a transit mode (:data:`TRANSITS`); else a :class:`SceneError` naming ``name``."""
    return _one_of(value, TRANSITS, name)


def check_switch_cost(value: Any, name: str) -> float:
    """``value`` as a switch cost in metres (>= 0); else a :class:`SceneError` naming ``name``.

    >>> check_switch_cost(0, "planner.switch_cost")
    0.0
    >>> check_switch_cost(-0.1, "planner.switch_cost")
    Traceback (most recent call last):
    ...
    planner.fields.SceneError: planner.switch_cost: must be >= 0, got -0.1
    """
    cost = number(value, name)
    if cost < 0:
        raise SceneError(name, f"must be >= 0, got {value!r}")
    return cost


def check_seed(value: Any, name: str) -> int:
    """``value`` as a planner seed; else a :class:`SceneError` naming ``name`` (a field or a flag)."""
    seed = integer(value, name)
    if not 1 <= seed <= MAX_SEED:
        raise SceneError(name, f"must be an integer in 1..{MAX_SEED}, got {seed}")
    return seed


def check_time_limit(value: Any, name: str) -> float:
    """``value`` as a planning time limit in seconds; else a :class:`SceneError` naming ``name``."""
    limit = number(value, name, positive=True)
    if limit > MAX_TIME_LIMIT:
        raise SceneError(name, f"must be at most {MAX_TIME_LIMIT:g} s, got {value!r}")
    return limit
