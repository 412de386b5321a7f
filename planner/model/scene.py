"""Scene files: the part, the pusher, the table and the task, read from YAML and validated.

Every problem is reported as a :class:`~planner.model.fields.SceneError` naming the offending field, so the command
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
from numpy.typing import ArrayLike

from mechanics import Slider, wrap_angle

from .bodies import slider_at
from .fields import Limit, SceneError, integer, keys, member, number, shown, vector

__all__ = ["ANGLE", "LENGTH", "MAX_NODES", "MAX_SCENE_BYTES", "MIN_SIZE", "MU_RANGE",
           "DEFAULT_PLANNER", "DEFAULT_REGIONS", "DEFAULT_SWITCH_COST", "DEFAULT_TRANSIT", "REGIONS", "TRANSITS",
           "check_optimize", "check_switch_cost", "check_transit", "MAX_OPTIMIZE", "MAX_SEED", "MAX_TIME_LIMIT", "SceneError", "Pusher", "PlannerOptions", "Scene",
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
#: The planner used when neither the scene nor the caller names one (chosen by planner.bench.planners).
DEFAULT_PLANNER = "rrt"
#: Seeds are OMPL's ``std::uint_fast32_t``: 32 bits is the most every platform takes.
MAX_SEED = 2**32 - 1
#: Most improvement rounds (``planner.optimize``): each is a search as long as the first.
MAX_OPTIMIZE = 100
#: One day. OMPL's deadline (now + limit) overflows for limits of some years and then ends the
#: search at once, so a huge or infinite limit would report failure without having searched.
MAX_TIME_LIMIT = 86400.0
#: Longest scene name in bytes: it names files, which most file systems cap at 255 bytes.
_MAX_NAME_BYTES = 200
#: Every coordinate and length of a scene, in metres: a kilometre is far beyond any table, keeps
#: squares and areas far from overflow, and is where the recording's 32-bit floats still resolve
#: 0.1 mm (float64 resolves 1e-13 m there, so a MIN_SIZE feature anywhere is exact to 1e-7).
LENGTH = Limit(1e3, "m")
#: The pusher's width and depth and a box's sides, in metres (a micron): thinner is no body.
MIN_SIZE = 1e-6
#: Every angle of a scene, in degrees: 2777 turns, wrapped to within 1e-10 degrees. Beyond some
#: 1e16 degrees a float has no digits left below a turn, so the heading it meant is lost.
ANGLE = Limit(1e6, "degrees")
#: Friction coefficients read: from all but frictionless to all but a wall (a cone of 89.94 degrees
#: each side); far beyond them the cone's arithmetic underflows or overflows.
MU_RANGE = (1e-3, 1e3)
#: Largest scene file read: a scene is a few kilobytes; a megabyte holds parts of thousands of
#: vertices and still parses in a few seconds.
MAX_SCENE_BYTES = 1_000_000
#: Most values (nodes) a scene file may hold, counting each alias as all of the node it names:
#: a part of 30000 vertices, or a megabyte of plain numbers, and no more.
MAX_NODES = 100_000
#: Deepest nesting of lists and mappings read: a scene's own goes 5 deep (obstacles[0].box.center).
_MAX_DEPTH = 16


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
    optimize: int = 0  # improvement rounds after the first plan (planner.search.planning.plan)


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

    def within_tolerance(self, pose: ArrayLike, goal: ArrayLike | None = None) -> bool:
        """Whether ``pose`` ends the task: its origin within ``tolerance_position`` of ``goal``'s
        (default: the scene's goal) and its heading within ``tolerance_angle``. The one test of the
        tolerance: the search's goal test, the plan decoder and the certificates all use it.

        >>> scene = parse_scene({"slider": {"vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]]},
        ...     "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-1, -1], "max": [1, 1]},
        ...     "start": [0, 0, 0], "goal": [0.5, 0, 0]})
        >>> scene.within_tolerance([0.5, 0.01, 0.0]), scene.within_tolerance([0.5, 0.0101, 0.0])
        (True, False)
        >>> scene.within_tolerance([0.5, 0.0, math.radians(1.9)]), scene.within_tolerance([0.5, 0.0, math.radians(2.1)])
        (True, False)
        """
        g = self.goal if goal is None else goal
        return (math.hypot(pose[0] - g[0], pose[1] - g[1]) <= self.tolerance_position
                and abs(float(wrap_angle(pose[2] - g[2]))) <= self.tolerance_angle)

    def tolerance_slack(self, reach: float) -> float:
        """How far a point ``reach`` from the slider frame's origin may end from where it is at
        the goal, for a pose within tolerance: ``tolerance_position + reach * tolerance_angle``
        (a turn by ``a`` moves it ``2 reach sin(a / 2) <= reach a``).

        >>> from dataclasses import replace
        >>> scene = replace(parse_scene({"slider": {"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]},
        ...     "pusher": {"width": 0.5, "depth": 0.1, "mu": 0.5}, "workspace": {"min": [-3, -3], "max": [3, 3]},
        ...     "start": [0, 0, 0], "goal": [1, 0, 0]}), tolerance_angle=0.1)
        >>> round(scene.tolerance_slack(2.0), 12)
        0.21
        """
        return self.tolerance_position + reach * self.tolerance_angle


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
        with path.open("rb") as f:
            raw = f.read(MAX_SCENE_BYTES + 1)  # no more: a huge file or a device is refused unread
    except (OSError, ValueError) as err:  # ValueError: a NUL in the path
        raise SceneError("scene", f"cannot read {shown(str(path))}: {getattr(err, 'strerror', None) or err}") from None
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError("scene", f"{shown(str(path))} is larger than {MAX_SCENE_BYTES} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SceneError("scene", f"{shown(str(path))} is not UTF-8 text (bad byte at offset {err.start})") from None
    try:
        return _parse_yaml(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at {_position(mark)}" if mark else ""
        problem = getattr(err, "problem", None) or " ".join(str(err).split())  # some messages span two lines
        kind = "unsupported" if isinstance(err, _Refused) else "malformed"
        raise SceneError("scene", f"{kind} YAML{where}: {problem}") from None


def _parse_yaml(text: str) -> Any:
    """The document in ``text`` (YAML 1.2 core schema, :class:`_Loader`), once :func:`_check_events`
    and :func:`_check_keys` have found nothing to refuse."""
    _check_events(text)
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:  # an empty file
            return None
        _check_keys(node, "scene")
        return loader.construct_document(node)
    finally:
        loader.dispose()


class _Refused(yaml.MarkedYAMLError):
    """Valid YAML that a scene may not use."""


def _check_events(text: str) -> None:
    """Refuse, before anything is built, a document that nests or expands beyond bounds.

    An alias stands for all of the node it names, so a few hundred bytes of aliases of aliases
    expand to gigabytes: each node's size is counted with its aliases expanded, and a document
    may hold :data:`MAX_NODES` nodes and nest :data:`_MAX_DEPTH` deep (building it recurses).
    """
    done: dict[str, tuple[int, int]] = {}  # anchor -> (nodes, depth) of the node it names
    stack: list[list] = []  # open lists and mappings: [anchor, nodes so far, depth of the deepest child]
    # depth: how many lists and mappings a node nests, 0 for a scalar; it sits in len(stack) more.
    for event in yaml.parse(text, Loader=_Loader):
        if isinstance(event, yaml.CollectionStartEvent):
            stack.append([event.anchor, 1, 0])
            size, depth = 1, 0  # its depth is counted on the stack until it ends
        elif isinstance(event, yaml.AliasEvent):
            if event.anchor not in done:  # undefined, or inside the node it names: a loop
                raise _Refused(problem=f"alias *{event.anchor} does not name a whole node before it",
                               problem_mark=event.start_mark)
            size, depth = done[event.anchor]
        elif isinstance(event, yaml.CollectionEndEvent):
            anchor, size, deepest = stack.pop()
            depth = deepest + 1
            if anchor is not None:
                done[anchor] = size, depth
        elif isinstance(event, yaml.ScalarEvent):
            size, depth = 1, 0
            if event.anchor is not None:
                done[event.anchor] = size, depth
        else:  # stream and document boundaries
            continue
        if depth + len(stack) > _MAX_DEPTH:
            raise _Refused(problem=f"lists and mappings nest more than {_MAX_DEPTH} deep",
                           problem_mark=event.start_mark)
        if stack and not isinstance(event, yaml.CollectionStartEvent):
            stack[-1][1] += size
            stack[-1][2] = max(stack[-1][2], depth)
            size = stack[-1][1]
        if size > MAX_NODES:
            raise _Refused(problem=f"more than {MAX_NODES} values, counting what aliases stand for",
                           problem_mark=event.start_mark)


def _check_keys(node: yaml.Node, name: str) -> None:
    """Refuse a key given twice in any mapping under ``node`` (named ``name``): PyYAML would keep the
    last one silently, and an edit that added a second ``mu:`` would seem to do nothing."""
    if isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _check_keys(item, f"{name}[{i}]")
    elif isinstance(node, yaml.MappingNode):
        first: dict[tuple[str, str], yaml.Mark] = {}
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):  # a list or mapping as a key: refused when built
                continue
            field = member(name, key.value)
            if (key.tag, key.value) in first:
                raise SceneError(field, f"duplicate key (at {_position(first[key.tag, key.value])} "
                                        f"and {_position(key.start_mark)})")
            first[key.tag, key.value] = key.start_mark
            _check_keys(value, field)


def _position(mark: yaml.Mark) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}"


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # libyaml's parser, when PyYAML has it: 6 times faster
    """PyYAML's safe loader reading YAML 1.2's core schema, not YAML 1.1's.

    So ``1e-3`` is a number (YAML 1.1 wants ``1.0e-3``), ``017`` is 17 (not octal 15; octal is
    ``0o17``), and ``1:30`` (not 90), ``yes``, ``on`` and ``2001-12-14`` are strings; merge keys
    (``<<``) are plain keys and only the core tags (``!!str``, ``!!int``, ``!!float``, ``!!bool``,
    ``!!null``, ``!!seq``, ``!!map``) are known.
    """

    yaml_implicit_resolvers: dict = {}
    yaml_constructors: dict = {}

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        return yaml.constructor.BaseConstructor.construct_mapping(self, node, deep)  # without 1.1's merge keys


# YAML 1.2 core schema (§10.3.2); ints before floats, which also match "1".
_NULL = re.compile(r"(?:~|null|Null|NULL|)\Z")
_BOOL = re.compile(r"(?:true|True|TRUE|false|False|FALSE)\Z")
_INT = re.compile(r"(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)\Z")
_FLOAT = re.compile(r"(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))\Z")
for _tag, _pattern, _first in (("null", _NULL, ["~", "n", "N", ""]), ("bool", _BOOL, list("tTfF")),
                               ("int", _INT, list("-+0123456789")), ("float", _FLOAT, list("-+.0123456789"))):
    _Loader.add_implicit_resolver(f"tag:yaml.org,2002:{_tag}", _pattern, _first)


def _scalar(loader: _Loader, node: yaml.ScalarNode, pattern: re.Pattern, kind: str) -> str:
    """The text of ``node``, which its tag says is a ``kind``: it must read as one by YAML 1.2."""
    text = loader.construct_scalar(node)
    if not pattern.match(text):
        raise yaml.constructor.ConstructorError(problem=f"{shown(text)} is not a YAML 1.2 {kind}",
                                                problem_mark=node.start_mark)
    return text


def _construct_bool(loader: _Loader, node: yaml.ScalarNode) -> bool:
    return _scalar(loader, node, _BOOL, "boolean").lower() == "true"


def _construct_int(loader: _Loader, node: yaml.ScalarNode) -> int:
    text = _scalar(loader, node, _INT, "integer")
    try:
        return int(text[2:], 8 if text[1] == "o" else 16) if text[:2] in ("0o", "0x") else int(text)
    except ValueError:  # Python reads at most 4300 digits (sys.get_int_max_str_digits)
        raise yaml.constructor.ConstructorError(problem=f"an integer of {len(text)} digits is too long",
                                                problem_mark=node.start_mark) from None


def _construct_float(loader: _Loader, node: yaml.ScalarNode) -> float:
    text = _scalar(loader, node, _FLOAT, "number").lower()
    return float(text.replace(".inf", "inf").replace(".nan", "nan"))


for _tag, _constructor in (("null", yaml.SafeLoader.construct_yaml_null), ("bool", _construct_bool),
                           ("int", _construct_int), ("float", _construct_float),
                           ("str", yaml.SafeLoader.construct_yaml_str), ("seq", yaml.SafeLoader.construct_yaml_seq),
                           ("map", yaml.SafeLoader.construct_yaml_map)):
    _Loader.add_constructor(f"tag:yaml.org,2002:{_tag}", _constructor)
_Loader.add_constructor(None, yaml.SafeLoader.construct_undefined)  # any other tag is an error


def _points(value: Any, name: str) -> np.ndarray:
    if not isinstance(value, (list, tuple)):
        raise SceneError(name, "must be a list of [x, y] points")
    if len(value) < 3:
        raise SceneError(name, f"needs at least 3 vertices, got {len(value)}")
    return np.array([vector(p, f"{name}[{i}]", 2, LENGTH) for i, p in enumerate(value)])


def _polygon(value: Any, name: str) -> shapely.Polygon:
    return _simple_polygon(_points(value, name), name)


def _simple_polygon(pts: np.ndarray, name: str) -> shapely.Polygon:
    # Area first: the ring of collinear points doubles back on itself, and "self-intersecting"
    # would send the reader looking for a crossing. The threshold is the one Slider uses,
    # area <= 1e-12 * max(1, extent) ** 2, compared by square roots so that no square overflows.
    with np.errstate(over="ignore"):  # an extent beyond a float is inf, and no zero area
        extent = float(np.ptp(pts))
    if math.sqrt(shapely.MultiPoint(pts).convex_hull.area) <= 1e-6 * max(1.0, extent):
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
    cx, cy = vector(box["center"], f"{name}.box.center", 2, LENGTH)
    w, h = vector(box["size"], f"{name}.box.size", 2, LENGTH)
    if not (w > 0 and h > 0):
        raise SceneError(f"{name}.box.size", f"must be positive, got {shown(box['size'])}")
    _at_least_min_size(min(w, h), f"{name}.box.size", box["size"])
    angle = math.radians(number(box.get("angle", 0.0), f"{name}.box.angle", limit=ANGLE))
    corners = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    return shapely.Polygon(corners @ rot.T + [cx, cy])


def _slider(value: Any) -> Slider:
    spec = keys(value, "slider", ("vertices",), ("cf", "cf_uncertainty"))
    vertices = _points(spec["vertices"], "slider.vertices")
    _simple_polygon(vertices, "slider.vertices")
    # A repeated vertex makes an edge of no length, with no normal to push along; shapely accepts it.
    # Nearly repeated is as bad: the edge's direction is rounding noise, or its square underflows to 0.
    repeated = np.flatnonzero(np.hypot(*(vertices - np.roll(vertices, -1, axis=0)).T) < MIN_SIZE)
    if len(repeated):
        k = int(repeated[0])
        raise SceneError("slider.vertices", f"vertices {k} and {(k + 1) % len(vertices)} coincide (closer than "
                                            f"{MIN_SIZE:g} m), so edge {k} has no length (do not repeat the first "
                                            "vertex at the end)")
    try:
        part = Slider(vertices)
    except ValueError as err:
        raise SceneError("slider.vertices", str(err)) from None
    if not part.pushable_edges:  # a star: otherwise each edge would be refused later, as unstable
        raise SceneError("slider.vertices", "no edge lies on the part's convex hull, so a flat pusher cannot push "
                                            "any (each edge has a vertex beyond its line)")
    if "cf" not in spec:
        return part
    cf = vector(spec["cf"], "slider.cf", 2, LENGTH)  # outside the try: a SceneError is a ValueError too
    try:
        return Slider(vertices, cf)
    except ValueError as err:
        raise SceneError("slider.cf", str(err)) from None


def _pusher(value: Any, slider: Slider) -> Pusher:
    spec = keys(value, "pusher", ("width", "depth", "mu"), ("edges", "transit"))
    width, depth = (_at_least_min_size(number(spec[key], f"pusher.{key}", positive=True, limit=LENGTH),
                                       f"pusher.{key}", spec[key]) for key in ("width", "depth"))
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
    """``pusher.mu``: a number in :data:`MU_RANGE`, or an interval ``[low, high]`` in it, ``low <= high``."""
    interval = isinstance(value, (list, tuple))
    if interval:
        low, high = vector(value, "pusher.mu", 2)
        if not 0 < low <= high:
            raise SceneError("pusher.mu", f"an interval must be [low, high] with 0 < low <= high, got {shown(value)}")
    else:
        low = high = number(value, "pusher.mu", positive=True)
    if not (MU_RANGE[0] <= low and high <= MU_RANGE[1]):
        raise SceneError("pusher.mu", f"must be from {MU_RANGE[0]:g} to {MU_RANGE[1]:g}, got {shown(value)}")
    return float(low), float(high) if interval else None


def _at_least_min_size(size: float, name: str, given: Any) -> float:
    """``size``, the least dimension of a body, if it is at least :data:`MIN_SIZE` (``given`` is
    the field's value, for the message)."""
    if size < MIN_SIZE:
        raise SceneError(name, f"must be at least {MIN_SIZE:g} m, got {shown(given)}")
    return size


def _pose(value: Any, name: str, slider: Slider, obstacles: tuple[shapely.Polygon, ...],
          workspace: tuple[float, float, float, float]) -> np.ndarray:
    """A pose ``[x, y, degrees]`` as ``(x, y, radians)`` with the angle in ``[-pi, pi)``, as the
    plan's segments have theirs; the part there must be in the workspace and clear of obstacles."""
    x, y, theta = vector(value, name, 3)
    LENGTH.check(x, f"{name}[0]")
    LENGTH.check(y, f"{name}[1]")
    pose = np.array([x, y, float(wrap_angle(math.radians(ANGLE.check(theta, f"{name}[2]"))))])
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
    lo, hi = vector(ws["min"], "workspace.min", 2, LENGTH), vector(ws["max"], "workspace.max", 2, LENGTH)
    if not np.all(hi > lo):
        raise SceneError("workspace", f"is empty or inverted: max {hi.tolist()} must exceed min {lo.tolist()}")
    workspace = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    start = _pose(spec["start"], "start", slider, obstacles, workspace)
    goal = _pose(spec["goal"], "goal", slider, obstacles, workspace)
    tol = keys(spec.get("tolerance", {}), "tolerance", (), ("position", "angle"))
    tol_pos = number(tol.get("position", 0.01), "tolerance.position", positive=True, limit=LENGTH)
    tol_ang = math.radians(number(tol.get("angle", 2.0), "tolerance.angle", positive=True, limit=ANGLE))
    opts = keys(spec.get("planner", {}), "planner", (),
                ("name", "time_limit", "seed", "regions", "switch_cost", "optimize"))
    planner = PlannerOptions(
        name=_one_of(opts.get("name", DEFAULT_PLANNER), PLANNERS, "planner.name"),
        time_limit=check_time_limit(opts.get("time_limit", PlannerOptions.time_limit), "planner.time_limit"),
        seed=check_seed(opts.get("seed", PlannerOptions.seed), "planner.seed"),
        regions=check_regions(opts.get("regions", DEFAULT_REGIONS), "planner.regions"),
        switch_cost=check_switch_cost(opts.get("switch_cost", DEFAULT_SWITCH_COST), "planner.switch_cost"),
        optimize=check_optimize(opts.get("optimize", PlannerOptions.optimize), "planner.optimize"),
    )
    return Scene(name, slider, pusher, obstacles, workspace, start, goal, tol_pos, tol_ang, planner, path,
                 cf_uncertainty)


def _cf_uncertainty(spec: dict, slider: Slider) -> float:
    """``slider.cf_uncertainty``: the radius (>= 0, less than the part's radius) of the disk about
    the CF that holds the true CF."""
    radius = number(spec.get("cf_uncertainty", 0.0), "slider.cf_uncertainty")
    if not 0 <= radius < slider.radius:
        raise SceneError("slider.cf_uncertainty", f"must be >= 0 and less than the part's radius "
                                                  f"{slider.radius:.4g}, got {shown(radius)}")
    return radius


def _name(value: Any) -> str:
    # The name names the output files, so it must make a plain file name.
    if not isinstance(value, str) or not value or not value.isprintable() or any(c in value for c in "/\\"):
        raise SceneError("name", f"must be a plain non-empty string, got {shown(value)}")
    if len(value.encode()) > _MAX_NAME_BYTES:
        raise SceneError("name", f"must be at most {_MAX_NAME_BYTES} bytes long, got {len(value.encode())}")
    return value


def _one_of(value: Any, choices: tuple[str, ...], name: str) -> str:
    if value not in choices:
        raise SceneError(name, f"must be one of {', '.join(choices)}, got {shown(value)}")
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
    planner.model.fields.SceneError: planner.switch_cost: must be >= 0, got -0.1
    """
    cost = number(value, name, limit=LENGTH)
    if cost < 0:
        raise SceneError(name, f"must be >= 0, got {shown(value)}")
    return cost


def check_optimize(value: Any, name: str) -> int:
    """``value`` as a number of improvement rounds (0..:data:`MAX_OPTIMIZE`); else a
    :class:`SceneError` naming ``name``.

    >>> check_optimize(3, "planner.optimize")
    3
    >>> check_optimize(-1, "--optimize")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: --optimize: must be an integer in 0..100, got -1
    """
    rounds = integer(value, name)
    if not 0 <= rounds <= MAX_OPTIMIZE:
        raise SceneError(name, f"must be an integer in 0..{MAX_OPTIMIZE}, got {rounds}")
    return rounds


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
        raise SceneError(name, f"must be at most {MAX_TIME_LIMIT:g} s, got {shown(value)}")
    return limit
