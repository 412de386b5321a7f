"""Scene files: the parts, the pusher, the table and the task, read from YAML and validated, and
written back in the plain schema.

The file is read by the hardened YAML reader of :mod:`.yaml_file`; its ``planner:`` block and
``pusher.transit`` are checked by :mod:`.options` and read into one
:class:`~planner.model.options.PlannerOptions`, the scene's :attr:`~planner.model.scene.Scene.options`.
Every problem is reported as a :class:`~planner.model.fields.SceneError` naming the offending
field, so the command line can print one line and exit 1. The format is documented in the
README. A mapping with ``parts:`` describes several parts (README, "Several parts"); one with
``slider:``, ``start:`` and ``goal:`` a scene of one part (:data:`~planner.model.scene.ONE_PART`).

>>> [load_scene(f).names for f in ("scenes/battery.yaml", "scenes/parts/swap.yaml")]
[('part',), ('red', 'blue')]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import yaml
from numpy.typing import ArrayLike

from mechanics import Slider, wrap_angle

from .bodies import slider_at
from .files import write_atomic
from .fields import ANGLE, LENGTH, SceneError, integer, keys, number, shown, vector
from .options import DEFAULT_TRANSIT, PlannerOptions, check_transit
from .camera import Camera, read_camera
from .robot import Robot, read_robot
from .scale import check_scale
from .scene import OBSTACLE_HEIGHT, ONE_PART, Part, Pusher, Scene
from .yaml_file import read_yaml

__all__ = ["MIN_SIZE", "MIN_TOLERANCE", "MU_RANGE", "PLANNER_KEYS", "Table", "load_scene", "parse_scene",
           "placement_fault", "plain_scene", "read_cf_uncertainty", "read_edges", "read_name", "read_pose",
           "read_pusher", "read_slider", "read_table", "write_scene"]

#: The keys of a scene's ``planner:`` block: the options but ``transit``, which a file gives as ``pusher.transit``.
PLANNER_KEYS = ("name", "time_limit", "seed", "regions", "switch_cost", "optimize", "margin")
#: Longest scene name in bytes: it names files, which most file systems cap at 255 bytes.
_MAX_NAME_BYTES = 200
#: The pusher's width and depth and a box's sides, in metres (a micron): thinner is no body.
MIN_SIZE = 1e-6
#: Friction coefficients read: from all but frictionless to all but a wall (a cone of 89.94 degrees
#: each side); far beyond them the cone's arithmetic underflows or overflows.
MU_RANGE = (1e-3, 1e3)
#: Least goal tolerance, in metres per metre of the table's extent (and in radians): a hundred times
#: the rounding a plan's composed poses carry (about 1e-11), so that "within tolerance" is decided
#: by the plan, not by rounding.
MIN_TOLERANCE = 1e-9


#: The keys of one part of ``parts:``: those of ``slider`` (or a CAD file's) and these.
_PART_KEYS = ("name", "start", "goal", "edges")
#: The keys of a scene of one part that a tray, with its ``parts:``, does not have.
ONE_PART_KEYS = ("slider", "start", "goal")


def load_scene(path: str | Path) -> Scene:
    """Read and validate a YAML scene file (either form, module docstring).

    Raises
    ------
    SceneError
        If the file cannot be read or any field is missing, unknown or invalid.
    """
    path = Path(path)
    return parse_scene(read_yaml(path, "scene"), default_name=path.stem, path=str(path))


def plain_scene(scene: Scene, options: PlannerOptions | None = None) -> dict[str, Any]:
    """``scene`` as :func:`parse_scene` reads it back, in the plain schema: every polygon as its
    vertices in metres (obstacle boxes and CAD files resolved), poses in degrees, the CF and the
    pushed edges written out; a scene of several parts (or of one not named
    :data:`~planner.model.scene.ONE_PART`) as ``parts:``. Its options are ``options`` (default:
    the scene's own), as a file gives them: the ``planner:`` block and ``pusher.transit``.

    >>> scene = load_scene("scenes/battery.yaml")
    >>> data = plain_scene(scene)
    >>> data["slider"]["cf"], data["pusher"]["edges"], len(data["obstacles"][0]["polygon"])
    ([0.0, 0.0], [3], 4)
    >>> again = parse_scene(data)
    >>> again.slider.vertices.tolist() == scene.slider.vertices.tolist(), again.obstacles == scene.obstacles
    (True, True)
    >>> tray = plain_scene(load_scene("scenes/parts/swap.yaml"))
    >>> [p["name"] for p in tray["parts"]], parse_scene(tray).names
    (['red', 'blue'], ('red', 'blue'))
    """
    pusher = scene.pusher
    options = scene.options if options is None else options
    pusher_data = {"width": pusher.width, "depth": pusher.depth,
                   "mu": pusher.mu if pusher.mu_high is None else [pusher.mu, pusher.mu_high], "transit": options.transit}
    table = {"obstacles": [{"polygon": np.asarray(o.exterior.coords)[:-1].tolist(), "height": h}
                           for o, h in zip(scene.obstacles, scene.obstacle_heights)],
             "workspace": {"min": list(scene.workspace[:2]), "max": list(scene.workspace[2:])},
             "tolerance": {"position": scene.tolerance_position, "angle": _degrees(scene.tolerance_angle)},
             "planner": {key: getattr(options, key) for key in PLANNER_KEYS} | {"margin": options.margin.to_dict()},
             **({"robot": scene.robot.to_dict()} if scene.robot is not None else {}),
             **({"camera": scene.camera.to_dict()} if scene.camera is not None else {})}
    if scene.names == (ONE_PART,):
        part = scene.part()
        return {"name": scene.name, "slider": _plain_part(part), "pusher": {**pusher_data, "edges": list(part.edges)},
                "start": _plain_pose(part.start), "goal": _plain_pose(part.goal), **table}
    parts = [{"name": p.name, **_plain_part(p), "edges": list(p.edges), "start": _plain_pose(p.start),
              "goal": _plain_pose(p.goal)} for p in scene.parts]
    return {"name": scene.name, "parts": parts, "pusher": pusher_data, **table}


def _plain_part(part: Part) -> dict[str, Any]:
    return {"vertices": part.slider.vertices.tolist(), "cf": part.slider.cf.tolist(),
            "cf_uncertainty": part.cf_uncertainty}


def _plain_pose(pose: np.ndarray) -> list[float]:
    return [*pose[:2].tolist(), _degrees(pose[2])]


def _degrees(radians: float) -> float:
    """``radians`` in degrees, to 1e-10 of a degree (as angles are read, :data:`.fields.ANGLE`), so
    that the degrees a scene gave come back as given: 30, not 29.999999999999993."""
    return round(math.degrees(radians), 10) + 0.0  # no -0.0


def write_scene(scene: Scene, path: str | Path, options: PlannerOptions | None = None) -> None:
    """Write :func:`plain_scene` of ``scene`` and ``options`` (default: the scene's own) to
    ``path`` as YAML, atomically.

    Raises
    ------
    OSError
        Naming ``path``, if it cannot be written.
    """
    source = f" from {scene.path}" if scene.path else ""
    text = yaml.safe_dump(plain_scene(scene, options), sort_keys=False, default_flow_style=None, width=120)
    write_atomic(path, f"# The scene{source} as planned: plan --export-scene writes what the planner used.\n{text}")


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


def _obstacles(value: Any, name: str, folder: Path, notes: list[str]) -> tuple[list[shapely.Polygon], float]:
    """The obstacles of one entry of ``obstacles`` and their height: a polygon, a box, or those a
    file draws (each of its bodies, cut where it has holes: :func:`.cad.without_holes`), with an
    optional ``height`` (m, default :data:`.scene.OBSTACLE_HEIGHT`)."""
    if isinstance(value, dict) and "height" in value:
        height = number(value["height"], f"{name}.height", positive=True, limit=LENGTH)
        return _obstacles({k: v for k, v in value.items() if k != "height"}, name, folder, notes)[0], height
    return _outlines(value, name, folder, notes), OBSTACLE_HEIGHT


def _outlines(value: Any, name: str, folder: Path, notes: list[str]) -> list[shapely.Polygon]:
    """The outlines :func:`_obstacles` reads."""
    if isinstance(value, dict) and "file" in value:
        from .cad import FILE_KEYS, FILE_OPTIONS, read_shapes, without_holes

        shapes = read_shapes(keys(value, name, FILE_KEYS, FILE_OPTIONS), name, folder, notes)
        return [piece for shape in shapes for piece in without_holes(shape.region)]
    if not isinstance(value, dict) or len(value) != 1 or next(iter(value)) not in ("polygon", "box"):
        raise SceneError(name, "must be {polygon: [[x, y], ...]}, {box: {center, size, angle}} or {file, units}, "
                               "each with an optional height")
    if "polygon" in value:
        return [_polygon(value["polygon"], f"{name}.polygon")]
    box = keys(value["box"], f"{name}.box", ("center", "size"), ("angle",))
    cx, cy = vector(box["center"], f"{name}.box.center", 2, LENGTH)
    w, h = vector(box["size"], f"{name}.box.size", 2, LENGTH)
    if not (w > 0 and h > 0):
        raise SceneError(f"{name}.box.size", f"must be positive, got {shown(box['size'])}")
    _at_least_min_size(min(w, h), f"{name}.box.size", box["size"])
    angle = math.radians(number(box.get("angle", 0.0), f"{name}.box.angle", limit=ANGLE))
    corners = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    return [shapely.Polygon(corners @ rot.T + [cx, cy])]


def read_slider(value: Any, folder: Path, notes: list[str], pusher: Pusher,
                workspace: tuple[float, float, float, float], name: str = "slider", more: tuple[str, ...] = ()) -> Slider:
    """The part ``value`` describes (its vertices or a CAD file, and its CF), checked, also for
    a size that suits ``pusher`` and ``workspace`` (:func:`.scale.check_scale`); errors name the
    fields under ``name``, and ``more`` are further keys ``value`` may hold (read by the caller: a
    multi-part scene's name, start and goal)."""
    if isinstance(value, dict) and "file" in value:
        return _slider_from_file(value, folder, notes, pusher, workspace, name, more)
    spec = keys(value, name, ("vertices",), ("cf", "cf_uncertainty") + more)
    vertices = _points(spec["vertices"], f"{name}.vertices")
    check_scale(vertices, pusher.width, workspace, f"{name}.vertices", None)
    return _checked_slider(vertices, spec, f"{name}.vertices", name)


def _slider_from_file(value: dict, folder: Path, notes: list[str], pusher: Pusher,
                      workspace: tuple[float, float, float, float], name: str, more: tuple[str, ...]) -> Slider:
    """The part a file draws: its outline is what the pusher touches, and its default CF the
    centroid of its footprint, holes left out (a hole carries no weight). ``more`` are the keys
    of the part's own (a part of ``parts:`` has a ``name``), not the file's."""
    from .cad import FILE_KEYS, FILE_OPTIONS, read_shapes

    spec = keys(value, name, FILE_KEYS, FILE_OPTIONS + ("cf", "cf_uncertainty") + more)
    shapes = read_shapes({k: v for k, v in spec.items() if k not in more}, name, folder, notes)
    if len(shapes) > 1:
        raise SceneError(f"{name}.file", f"holds {len(shapes)} parts: pick one with layer or object")
    (shape,) = shapes
    if shape.footprint.area <= 0:
        raise SceneError(f"{name}.file", "the part has no footprint on the table")
    vertices = np.asarray(shape.region.exterior.coords)[:-1]
    check_scale(vertices, pusher.width, workspace, f"{name}.units", spec["units"])
    cf = np.asarray(shape.footprint.centroid.coords[0])
    return _checked_slider(vertices, {"cf": cf.tolist(), **spec}, f"{name}.file", name)


def _checked_slider(vertices: np.ndarray, spec: dict, field: str, name: str) -> Slider:
    """The part of ``vertices`` and ``spec``'s ``cf`` (default: the area centroid), checked;
    ``field`` is where the vertices came from, ``name`` the part's field."""
    _simple_polygon(vertices, field)
    # A repeated vertex makes an edge of no length, with no normal to push along; shapely accepts it.
    # Nearly repeated is as bad: the edge's direction is rounding noise, or its square underflows to 0.
    repeated = np.flatnonzero(np.hypot(*(vertices - np.roll(vertices, -1, axis=0)).T) < MIN_SIZE)
    if len(repeated):
        k = int(repeated[0])
        raise SceneError(field, f"vertices {k} and {(k + 1) % len(vertices)} coincide (closer than "
                                f"{MIN_SIZE:g} m), so edge {k} has no length (do not repeat the first "
                                "vertex at the end)")
    try:
        part = Slider(vertices)
    except ValueError as err:
        raise SceneError(field, str(err)) from None
    if not part.pushable_edges:  # a star: otherwise each edge would be refused later, as unstable
        raise SceneError(field, "no edge lies on the part's convex hull, so a flat pusher cannot push "
                                "any (each edge has a vertex beyond its line)")
    if "cf" not in spec:
        return part
    cf = vector(spec["cf"], f"{name}.cf", 2, LENGTH)  # outside the try: a SceneError is a ValueError too
    try:
        return Slider(vertices, cf)
    except ValueError as err:
        raise SceneError(f"{name}.cf", str(err)) from None


def read_pusher(value: Any, one_part: bool) -> tuple[Pusher, Any, str]:
    """The pusher ``value`` describes, its ``edges`` as listed (None if not: every pushable
    edge), which only a scene of one part (``one_part``) may give: the parts of a scene with
    ``parts:`` list their own (:func:`read_edges`), and its ``transit``, checked: an option of the
    scene's (:func:`read_table`) that the file gives with the pusher."""
    spec = keys(value, "pusher", ("width", "depth", "mu"), ("edges", "transit") if one_part else ("transit",))
    width, depth = (_at_least_min_size(number(spec[key], f"pusher.{key}", positive=True, limit=LENGTH),
                                       f"pusher.{key}", spec[key]) for key in ("width", "depth"))
    mu, mu_high = _friction(spec["mu"])
    transit = check_transit(spec.get("transit", DEFAULT_TRANSIT), "pusher.transit")
    return Pusher(width, depth, mu, mu_high), spec.get("edges"), transit


def read_edges(listed: Any, slider: Slider, name: str) -> tuple[int, ...]:
    """The edges of ``slider`` listed at ``name`` (None: every pushable edge), checked."""
    if listed is None:
        return slider.pushable_edges
    if not isinstance(listed, (list, tuple)) or not listed:
        raise SceneError(name, "must be a non-empty list of edge indices")
    edges = []
    for i, e in enumerate(listed):
        e = integer(e, f"{name}[{i}]")
        if not 0 <= e < slider.n:
            raise SceneError(name, f"edge {e} does not exist (the part has edges 0..{slider.n - 1})")
        if not slider.is_pushable(e):
            raise SceneError(name, f"edge {e} is not on the convex hull, so a flat pusher cannot push it")
        if e in edges:
            raise SceneError(name, f"edge {e} is listed twice")
        edges.append(e)
    return tuple(edges)


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


def read_pose(value: Any, name: str, slider: Slider, obstacles: tuple[shapely.Polygon, ...],
              workspace: tuple[float, float, float, float]) -> np.ndarray:
    """A pose ``[x, y, degrees]`` as ``(x, y, radians)`` with the angle in ``[-pi, pi)``, as the
    plan's segments have theirs; the part there must be in the workspace and clear of obstacles."""
    x, y, theta = vector(value, name, 3)
    LENGTH.check(x, f"{name}[0]")
    LENGTH.check(y, f"{name}[1]")
    pose = np.array([x, y, float(wrap_angle(math.radians(ANGLE.check(theta, f"{name}[2]"))))])
    if (fault := placement_fault(slider, obstacles, workspace, pose)) is not None:
        raise SceneError(name, fault)
    return pose


def placement_fault(slider: Slider, obstacles: tuple[shapely.Polygon, ...],
                    workspace: tuple[float, float, float, float], pose: ArrayLike) -> str | None:
    """Why the part cannot be at ``pose`` (outside the workspace, or on an obstacle), or None."""
    body = slider_at(slider.polygon, pose)
    if not shapely.box(*workspace).contains(body):
        return "the part is not inside the workspace"
    for k, obstacle in enumerate(obstacles):
        if body.intersects(obstacle):
            return f"the part collides with obstacle {k}"
    return None


def parse_scene(data: Any, default_name: str = "scene", path: str | None = None) -> Scene:
    """Validate a scene given as the parsed YAML mapping (see :func:`load_scene`): with ``parts:``,
    several parts; else one, from ``slider:``, ``start:`` and ``goal:``. The files it names are
    relative to the folder of ``path`` (the working folder if None).

    Raises
    ------
    SceneError
        Naming the field at fault.
    """
    if isinstance(data, dict) and "parts" in data:
        return _parse_parts(data, default_name, path)
    required = ("slider", "pusher", "workspace", "start", "goal")
    optional = ("name", "obstacles", "tolerance", "planner", "robot", "camera")
    keys(data, "scene", (), required + optional, suggest=("parts",))  # a tray's "part:" is a typo of parts:
    if not any(key in data for key in ONE_PART_KEYS):  # neither form: say both, not what one part misses
        raise SceneError("parts", "missing: a scene has parts: (each with its own start and goal) or slider, start "
                                  "and goal (one part)")
    spec = keys(data, "scene", required, optional)
    name = read_name(spec.get("name", default_name))
    folder, notes = Path(path).parent if path else Path(), []
    pusher, listed, transit = read_pusher(spec["pusher"], True)
    table = read_table(spec, folder, notes, transit)  # the part's size is checked against both
    slider = read_slider(spec["slider"], folder, notes, pusher, table.workspace)
    cf_uncertainty = read_cf_uncertainty(spec["slider"], slider, "slider")
    edges = read_edges(listed, slider, "pusher.edges")
    start = read_pose(spec["start"], "start", slider, table.obstacles, table.workspace)
    goal = read_pose(spec["goal"], "goal", slider, table.obstacles, table.workspace)
    part = Part(ONE_PART, slider, start, goal, edges, cf_uncertainty)
    return Scene(name, (part,), pusher, table.obstacles, table.workspace, table.tolerance_position,
                 table.tolerance_angle, table.options, path, tuple(notes), table.robot, table.camera,
                 table.heights)


@dataclass(frozen=True)
class Table:
    """What every scene has besides its parts and pusher: obstacles, workspace, goal tolerance
    and the options the file asks for."""

    obstacles: tuple[shapely.Polygon, ...]
    workspace: tuple[float, float, float, float]
    tolerance_position: float
    tolerance_angle: float
    options: PlannerOptions
    robot: Robot | None = None
    camera: Camera | None = None
    heights: tuple[float, ...] = ()  # the obstacles' (Scene.heights)


def read_table(spec: dict, folder: Path, notes: list[str], transit: str) -> Table:
    """The :class:`Table` of a scene's mapping ``spec``, checked; CAD files are relative to
    ``folder``. Its options are the ``planner:`` block's with ``transit`` (the pusher's, checked
    by :func:`read_pusher`)."""
    obstacles_spec = [] if spec.get("obstacles") is None else spec["obstacles"]  # None: a bare "obstacles:"
    if not isinstance(obstacles_spec, list):
        raise SceneError("obstacles", "must be a list")
    read = [_obstacles(o, f"obstacles[{k}]", folder, notes) for k, o in enumerate(obstacles_spec)]
    obstacles = tuple(p for outlines, _ in read for p in outlines)
    heights = tuple(h for outlines, h in read for _ in outlines)
    ws = keys(spec["workspace"], "workspace", ("min", "max"))
    lo, hi = vector(ws["min"], "workspace.min", 2, LENGTH), vector(ws["max"], "workspace.max", 2, LENGTH)
    if not np.all(hi > lo):
        raise SceneError("workspace", f"is empty or inverted: max {hi.tolist()} must exceed min {lo.tolist()}")
    workspace = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    tol = keys(spec.get("tolerance", {}), "tolerance", (), ("position", "angle"))
    tol_pos = number(tol.get("position", 0.01), "tolerance.position", positive=True, limit=LENGTH)
    tol_ang = math.radians(number(tol.get("angle", 2.0), "tolerance.angle", positive=True, limit=ANGLE))
    # Plans compose many exponentials: their poses carry rounding of about 1e-11 of the table's size
    # (and radian). A tolerance below what that resolves could not tell a plan that ends within it.
    size = max(1.0, float(np.max(np.abs(workspace))))
    least = float(f"{MIN_TOLERANCE * size:.3g}")  # the limit as the message shows it
    if tol_pos < least:
        raise SceneError("tolerance.position", f"must be at least {least:g} m (the rounding of a plan's poses on "
                                               f"this table is about {1e-11 * size:g} m), got {tol_pos:g}")
    if tol_ang < MIN_TOLERANCE:
        raise SceneError("tolerance.angle", f"must be at least {math.degrees(MIN_TOLERANCE):g} degrees (the rounding "
                                            f"of a plan's headings is about 1e-11 rad), got {math.degrees(tol_ang):g}")
    opts = keys(spec.get("planner", {}), "planner", (), PLANNER_KEYS)
    return Table(obstacles, workspace, tol_pos, tol_ang,
                 PlannerOptions().merged({**opts, "transit": transit}, prefix="planner."),
                 None if spec.get("robot") is None else read_robot(spec["robot"], workspace),
                 read_camera(spec["camera"], workspace) if "camera" in spec else None, heights)


def read_cf_uncertainty(spec: dict, slider: Slider, name: str) -> float:
    """``<name>.cf_uncertainty``: the radius (>= 0, less than the part's radius) of the disk about
    the CF that holds the true CF."""
    radius = number(spec.get("cf_uncertainty", 0.0), f"{name}.cf_uncertainty")
    if not 0 <= radius < slider.radius:
        raise SceneError(f"{name}.cf_uncertainty", f"must be >= 0 and less than the part's radius "
                                                  f"{slider.radius:.4g}, got {shown(radius)}")
    return radius


def read_name(value: Any) -> str:
    # The name names the output files, so it must make a plain file name.
    if not isinstance(value, str) or not value or not value.isprintable() or any(c in value for c in "/\\"):
        raise SceneError("name", f"must be a plain non-empty string, got {shown(value)}")
    if len(value.encode()) > _MAX_NAME_BYTES:
        raise SceneError("name", f"must be at most {_MAX_NAME_BYTES} bytes long, got {len(value.encode())}")
    return value


def _parse_parts(data: dict, default_name: str, path: str | None) -> Scene:
    """:func:`parse_scene` of a mapping with ``parts:``."""
    for key in ONE_PART_KEYS:
        if key in data:
            raise SceneError(key, "a scene has parts: (each with its own start and goal) or slider, start and goal, "
                                  "not both")
    spec = keys(data, "scene", ("parts", "pusher", "workspace"),
                ("name", "obstacles", "tolerance", "planner", "robot", "camera"))
    name = read_name(spec.get("name", default_name))
    folder, notes = Path(path).parent if path else Path(), []
    pusher, _, transit = read_pusher(spec["pusher"], False)
    table = read_table(spec, folder, notes, transit)
    listed = spec["parts"]
    if not isinstance(listed, list) or not listed:
        raise SceneError("parts", "must be a non-empty list of parts, each with name, vertices, start and goal")
    parts: list[Part] = []
    for i, item in enumerate(listed):
        field_name = f"parts[{i}]"
        slider = read_slider(item, folder, notes, pusher, table.workspace, field_name, _PART_KEYS)
        for key in ("name", "start", "goal"):
            if key not in item:
                raise SceneError(f"{field_name}.{key}", "missing")
        part_name = _part_name(item["name"], f"{field_name}.name")
        if part_name in (p.name for p in parts):
            raise SceneError(f"{field_name}.name", f"part {shown(part_name)} is named twice")
        poses = [read_pose(item[k], f"{field_name}.{k}", slider, table.obstacles, table.workspace) for k in ("start", "goal")]
        parts.append(Part(part_name, slider, *poses, read_edges(item.get("edges"), slider, f"{field_name}.edges"),
                          read_cf_uncertainty(item, slider, field_name)))
    for which in ("start", "goal"):
        _apart(parts, which)
    return Scene(name, tuple(parts), pusher, table.obstacles, table.workspace, table.tolerance_position,
                 table.tolerance_angle, table.options, path, tuple(notes), table.robot, table.camera,
                 table.heights)


def _part_name(value: Any, field_name: str) -> str:
    """A part's name: what names a scene (it may name files) and no longer than a label."""
    try:
        return read_name(value)
    except SceneError as err:
        raise SceneError(field_name, err.problem) from None


def _apart(parts: list[Part], which: str) -> None:
    """Refuse two parts that touch or overlap at their ``which`` poses (``'start'`` or ``'goal'``),
    naming both."""
    bodies = [slider_at(p.slider.polygon, getattr(p, which)) for p in parts]
    i, j = shapely.STRtree(bodies).query(bodies, predicate="intersects")
    for a, b in zip(i.tolist(), j.tolist()):
        if a < b:
            raise SceneError(f"parts[{b}].{which}", f"part {shown(parts[b].name)} overlaps part "
                                                    f"{shown(parts[a].name)} at their {which}s")

