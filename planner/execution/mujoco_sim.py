"""Whole plans run open-loop in MuJoCo: the pusher follows the plan's trajectory blindly.

:mod:`.verify` re-simulates each push with the quasi-static mechanics the planner assumes. Here
the plan meets a physics engine that assumes none of it: the part is a rigid body with mass on
the table, the pusher a kinematic body driven along :func:`.trajectory.trajectory` (lifted to
``z`` in a lift's flight), and every segment runs after the last with no correction.

**The model** (:func:`mjcf`). A table (plane), the workspace walls and the obstacles as prisms
(non-convex ones as their :func:`~planner.model.bodies.convex_pieces`), the part as one body made
of the convex pieces of its polygon (thin prisms), and the pusher as a prism of the pusher body's
outline. The part does not lie on its face: it stands on a few small spherical *feet*, each a
body of its own that slides vertically in the part and weighs its share ``w_i`` of the support
(``w_i`` the foot's weight in the distribution, :class:`Feet`), so its normal force on the table,
hence its friction, is exactly that share; the part's centre of mass is the support's centre (the
CF, or the CF moved by an offset). So each foot set is one support distribution: the barycentric
weights of three feet round the centre, or a grid's weights moved to put the centre there
(:func:`mechanics.quasistatic.grid_support`). The part itself moves in the plane only (x, y and
heading): a free part rocked on its feet under the pusher's moment about the table, and the
pusher's friction, which with a vertical face also acts vertically, carried some of its weight,
so the feet's loads, hence the distribution, were not the ones meant. Only the listed contact
pairs exist: feet-table (friction :data:`TABLE_MU`), pusher-part (the planned
``scene.pusher.mu``, or ``mu=``) and part-obstacle (to detect collisions).

The pusher is not a mocap body: contact friction sees a mocap body's velocity as zero, so the
part's friction against a moving pusher would be computed as if it were still (the part slid
along the face by a fifth of the push). It is a heavy body on x, y, z and heading joints whose
positions and velocities are set to the trajectory before every step.

**Quasi-static accuracy.** The trajectory is slow (inertial forces a sixth of friction at most),
so what matters is that sticking contacts stick and sliding ones slide at the friction limit.
Elliptic friction cones are MuJoCo's exact Coulomb cones (pyramidal ones, linearised, let a
three-foot part turn by up to 0.02 rad more than planned on the battery), solved by the Newton
solver to a tolerance of 1e-10 at every step, with ``impratio`` 10: friction ten times stiffer than
the normal direction, since MuJoCo's soft friction lets a sticking contact creep in proportion to
its load (on ``scenes/cluttered.yaml`` the pusher crept 1.4 mm along the face in one push at the
default 1, 0.3 mm at 10; a smaller step did not help, the no-slip post-pass less). The step, :data:`TIMESTEP` (2 ms), is a tenth of the
contacts' default time constant (0.02 s), and 1 ms or 0.5 ms change the battery's end by less
than 0.05 mm; stiffer contacts (time constants of a few steps) made the part chatter and slip by
millimetres. What remains is the soft contact's penetration of the pusher into the part, about
0.2 mm, which shows as the runs' deviation and "slip"; the slip threshold :data:`SLIP` is five
times that.

**What is measured** (:class:`Run`), at every trajectory sample: the part's simulated pose against
its planned one (during a push, the pusher frame's pose times the inverse of the contact pose; in
a transit, where the part was left), the pusher face's midpoint in the simulated part frame while
``contact`` is 1 (it should stay where it was when the push began: moving along the edge is
slip, away from it separation; measured per push, so that an error the part carries from earlier
pushes is deviation, not slip), and contacts of the part with walls or obstacles.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, relative_pose, transform_points, wrap_angle
from mechanics.quasistatic import grid_support, tripod_supports

from ..actions.transit import edge_contact_pose
from ..model.bodies import convex_pieces, pusher_frame_body, slider_at
from ..model.fields import SceneError
from ..model.files import write_atomic
from ..model.scene import Scene
from ..model.plan import Plan
from ..model.segments import Transit
from ..model.scene_file import placement_fault
from ..world.validity import CollisionModel
from .approach import first_edge, lead_in_pose
from .trajectory import Trajectory, planned_part, trajectory

__all__ = ["MISSING", "SLIP", "TABLE_MU", "TIMESTEP", "Feet", "Run", "Runs", "Simulation", "document", "feet", "mjcf",
           "needs_mujoco", "part_body", "part_pairs", "table", "World", "perturbations", "simulate", "support_centre", "write_mjcf"]

#: The one line ``plan --simulate`` prints (after ``plan: error: --simulate: ``) without MuJoCo.
MISSING = "needs MuJoCo: pip install 'stablepush[mujoco]'"
#: Part-table friction coefficient: the plan holds for any, so one fixed value.
TABLE_MU = 0.5
#: Integration step, s (module docstring, "Quasi-static accuracy").
TIMESTEP = 0.002
#: Slip threshold, m: the pusher's face midpoint may move this far in the part frame while pushing.
SLIP = 0.001
#: Part geometry: prism thickness, foot radius (m), mass (kg); obstacle and wall height (m).
THICKNESS, FOOT, MASS, WALL_HEIGHT = 0.004, 0.001, 0.1, 0.03
#: Mass of the pusher, kg: far heavier than the part, so a step's contact forces barely move it.
PUSHER_MASS = 1000.0
#: Time the part is left to settle on its feet before the pusher moves, s.
SETTLE = 0.1
#: Feet of a grid distribution (about).
GRID_FEET = 9
#: Step by which a knocked part is moved off the pusher, m.
BUMP_STEP = 0.0002


@dataclass(frozen=True)
class Feet:
    """A support distribution as feet: points (slider frame) and the centre of mass over them."""

    kind: str
    points: np.ndarray
    weights: np.ndarray  # summing to 1, their centre the support's
    centre: np.ndarray


def support_centre(scene: Scene, offset: ArrayLike) -> np.ndarray:
    """The CF moved by ``offset`` (slider frame), or :class:`SceneError` naming ``cf_offset``
    if that is not inside the part (no support on it has its centre there)."""
    centre = scene.slider.cf + np.asarray(offset, dtype=float)
    if not scene.slider.polygon.contains(shapely.Point(centre)):
        raise SceneError("cf_offset", f"puts the centre of pressure {np.round(centre, 6).tolist()} off the part")
    return centre


def feet(scene: Scene, n: int, seed: int = 1, offset: ArrayLike = (0.0, 0.0)) -> list[Feet]:
    """``n`` foot sets with their centre at the CF plus ``offset`` (slider frame): a grid of
    about :data:`GRID_FEET` feet, then alternately an extreme tripod (feet on the part's boundary,
    :func:`mechanics.quasistatic.tripod_supports`) and a random tripod (feet anywhere on the
    part), both round the centre and drawn from ``seed``.

    >>> from planner import load_scene
    >>> [f.kind for f in feet(load_scene("scenes/battery.yaml"), 4)]
    ['grid', 'extreme', 'random', 'extreme']
    """
    if n < 1:
        raise ValueError(f"need at least one distribution, got {n}")
    footprint, centre = scene.slider.polygon, support_centre(scene, offset)
    rng = np.random.default_rng(seed)
    try:
        grid = grid_support(footprint, GRID_FEET, cf=centre)
    except ValueError:  # the centre is outside the grid's hull: the extreme tripods still reach it
        grid = None
    out = [Feet("grid", grid.points, grid.weights, centre)] if grid is not None else []
    minx, miny, maxx, maxy = footprint.bounds
    while len(out) < n:
        if len(out) % 2:
            tripod = tripod_supports(footprint, centre, 1, rng)[0]
            out.append(Feet("extreme", tripod.points, tripod.weights, centre))
            continue
        points = rng.uniform([minx, miny], [maxx, maxy], size=(3, 2))
        a = np.vstack([points.T, np.ones(3)])
        if (shapely.contains_xy(footprint, points[:, 0], points[:, 1]).all()
                and abs(np.linalg.det(a)) > 1e-12 * footprint.area
                and (weights := np.linalg.solve(a, [*centre, 1.0])).min() >= 0.05):
            out.append(Feet("random", points, weights, centre))
    return out


def _numbers(values: ArrayLike) -> str:
    return " ".join(f"{v:.17g}" for v in np.ravel(values))


def _prism(name: str, outline: np.ndarray, bottom: float, top: float) -> str:
    """A mesh asset: the convex prism of ``outline`` between heights ``bottom`` and ``top``."""
    vertices = np.vstack([np.column_stack([outline, np.full(len(outline), z)]) for z in (bottom, top)])
    return f'<mesh name="{name}" vertex="{_numbers(vertices)}"/>'


def _second_moment(pieces: list[np.ndarray], centre: np.ndarray) -> float:
    """Polar second moment of area of the pieces about ``centre``, divided by their area."""
    total = area = 0.0
    for piece in pieces:
        p = piece - centre
        for b, c in zip(p[1:-1], p[2:]):  # a fan of triangles from p[0]
            u, v = b - p[0], c - p[0]
            piece_area = 0.5 * abs(float(u[0] * v[1] - u[1] * v[0]))
            total += piece_area / 6 * (p[0] @ p[0] + b @ b + c @ c + p[0] @ b + b @ c + c @ p[0])
            area += piece_area
    return total / area


def table(scene: Scene) -> tuple[list[str], list[str], list[str]]:
    """The MJCF of what stands on the table: mesh assets, world geoms (the workspace walls and the
    obstacles as prisms, non-convex ones as their convex pieces) and the names of those geoms."""
    assets, world = [], []
    xmin, ymin, xmax, ymax = scene.workspace
    wall = 0.05
    walls = [((xmin - wall / 2, (ymin + ymax) / 2), (wall / 2, (ymax - ymin) / 2 + wall)),
             ((xmax + wall / 2, (ymin + ymax) / 2), (wall / 2, (ymax - ymin) / 2 + wall)),
             (((xmin + xmax) / 2, ymin - wall / 2), ((xmax - xmin) / 2 + wall, wall / 2)),
             (((xmin + xmax) / 2, ymax + wall / 2), ((xmax - xmin) / 2 + wall, wall / 2))]
    blocks = [f"wall{k}" for k in range(4)]
    for name, (c, h) in zip(blocks, walls):
        world.append(f'<geom name="{name}" type="box" pos="{_numbers([*c, WALL_HEIGHT / 2])}" '
                     f'size="{_numbers([*h, WALL_HEIGHT / 2])}" rgba=".5 .5 .5 1"/>')
    for i, obstacle in enumerate(scene.obstacles):
        for j, piece in enumerate(convex_pieces(obstacle)):
            name = f"obstacle{i}_{j}"
            assets.append(_prism(name, piece, 0.0, WALL_HEIGHT))
            world.append(f'<geom name="{name}" type="mesh" mesh="{name}" rgba=".6 .3 .3 1"/>')
            blocks.append(name)
    return assets, world, blocks


def document(scene: Scene, assets: list[str], world: list[str], bodies: list[str], pairs: list[str],
             keys: list[str]) -> str:
    """The MJCF document of ``scene``: the options, the table plane, ``world``'s geoms, the part
    ``bodies``, the pusher (a prism of its outline on x, y, z and heading joints, last in the
    joints' order), the contact ``pairs`` and the ``keys``."""
    xmin, ymin, xmax, ymax = scene.workspace
    span = max(xmax - xmin, ymax - ymin)
    top = THICKNESS + 2 * FOOT + 0.01
    assets = assets + [_prism("pusher", pusher_frame_body(scene.pusher.width, scene.pusher.depth), 0.0, top)]
    return f"""<mujoco model={quoteattr(scene.name)}>
  <option timestep="{TIMESTEP}" cone="elliptic" impratio="10" solver="Newton" iterations="50" tolerance="1e-10"/>
  <default>
    <geom contype="0" conaffinity="0"/>
  </default>
  <asset>
    {chr(10).join('    ' + a for a in assets).strip()}
  </asset>
  <worldbody>
    <geom name="table" type="plane" size="{_numbers([span, span, 0.1])}" pos="{_numbers([(xmin + xmax) / 2, (ymin + ymax) / 2, 0])}" rgba=".9 .9 .85 1"/>
    {chr(10).join('    ' + w for w in world).strip()}
    {chr(10).join('    ' + b for b in bodies).strip()}
    <body name="pusher" gravcomp="1">
      <joint name="pusher_x" type="slide" axis="1 0 0"/>
      <joint name="pusher_y" type="slide" axis="0 1 0"/>
      <joint name="pusher_z" type="slide" axis="0 0 1"/>
      <joint name="pusher_theta" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{PUSHER_MASS}" diaginertia="{_numbers([PUSHER_MASS * 0.01] * 3)}"/>
      <geom name="pusher" type="mesh" mesh="pusher" rgba=".1 .1 .1 1"/>
    </body>
  </worldbody>
  <contact>
    {chr(10).join('    ' + p for p in pairs).strip()}
  </contact>
  <keyframe>
    {chr(10).join('    ' + k for k in keys).strip()}
  </keyframe>
</mujoco>
"""


def part_body(name: str, prefix: str, slider: Slider, support: Feet) -> tuple[list[str], str, list[str], list[str]]:
    """The MJCF of a part on ``support``'s feet, its body called ``name`` and its joints, geoms and
    feet ``<prefix>_x``..., ``<prefix><j>``, ``foot<prefix-less k>``: its mesh assets, the body, its
    geoms' names and its feet's table contacts. The part's frame is the slider frame; gravity
    acts at the support's centre (module docstring, "The model")."""
    pieces = convex_pieces(slider.polygon)
    assets, geoms, part, pairs = [], [], [], []
    for j, piece in enumerate(pieces):
        assets.append(_prism(f"{prefix}{j}", piece, -THICKNESS / 2, THICKNESS / 2))
        part.append(f'<geom name="{prefix}{j}" type="mesh" mesh="{prefix}{j}" rgba=".2 .4 .8 1"/>')
        geoms.append(f"{prefix}{j}")
    feet_name = prefix.replace("part", "foot")
    for k, (p, w) in enumerate(zip(support.points, support.weights)):
        # A foot slides vertically in the part and carries its share of the weight to the table.
        part.append(f'<body name="{feet_name}{k}" pos="{_numbers([*p, -THICKNESS / 2 - FOOT])}">'
                    f'<joint name="{feet_name}{k}" type="slide" axis="0 0 1"/>'
                    f'<inertial pos="0 0 0" mass="{w * MASS:.17g}" diaginertia="1e-9 1e-9 1e-9"/>'
                    f'<geom name="{feet_name}{k}" type="sphere" size="{FOOT}" rgba=".1 .1 .1 1"/></body>')
        pairs.append(f'<pair geom1="table" geom2="{feet_name}{k}" condim="3" friction="{TABLE_MU} {TABLE_MU} 0 0 0"/>')
    inertia = MASS * _second_moment(pieces, support.centre)
    height = THICKNESS / 2 + 2 * FOOT
    body = f"""<body name="{name}" pos="0 0 {height:.17g}">
      <joint name="{name}_x" type="slide" axis="1 0 0"/>
      <joint name="{name}_y" type="slide" axis="0 1 0"/>
      <joint name="{name}_theta" type="hinge" axis="0 0 1"/>
      <inertial pos="{_numbers([*support.centre, 0])}" mass="{MASS}" diaginertia="{_numbers([inertia / 2, inertia / 2, inertia])}"/>
      {chr(10).join('      ' + g for g in part).strip()}
    </body>"""
    return assets, body, geoms, pairs


def part_pairs(geoms: list[str], blocks: list[str], mu: float) -> list[str]:
    """The contacts of a part's ``geoms``: with the pusher (friction ``mu``), and with the walls
    and obstacles (``blocks``; frictionless, there only to be detected)."""
    pairs = []
    for g in geoms:
        pairs.append(f'<pair geom1="pusher" geom2="{g}" condim="3" friction="{mu} {mu} 0 0 0" />')
        pairs += [f'<pair geom1="{b}" geom2="{g}" condim="1"/>' for b in blocks]
    return pairs


def mjcf(scene: Scene, support: Feet, mu: float | None = None, start: ArrayLike | None = None,
         keys: ArrayLike | None = None) -> str:
    """The MuJoCo model (MJCF XML) of ``scene`` with the part on ``support``'s feet, starting at
    ``start`` (default: the scene's start), and pusher-part friction ``mu`` (default: the planned
    ``scene.pusher.mu``); module docstring, "The model".

    ``keys``, rows ``(t, part x, y, theta, pusher x, y, z, theta)``, become keyframes ``t=<t>``
    (the first named ``start``) so that a viewer can step along a run; without them the one
    keyframe ``start`` has the part at ``start`` and the pusher at the world origin."""
    mu = scene.pusher.mu if mu is None else mu
    assets, world, blocks = table(scene)
    part_assets, body, geoms, pairs = part_body("part", "part", scene.slider, support)
    pairs += part_pairs(geoms, blocks, mu)
    pose = scene.start if start is None else np.asarray(start, dtype=float)
    return document(scene, assets + part_assets, world, [body], pairs, _keyframes(pose, len(support.points), keys))


def _keyframes(start: np.ndarray, feet: int, keys: ArrayLike | None) -> list[str]:
    """``<key>`` elements: the joints in model order are the part's three, one per foot (at rest:
    0), then the pusher's four."""
    if keys is None:
        return [f'<key name="start" qpos="{_numbers([*start, *np.zeros(feet + 4)])}"/>']
    return [f'<key name="{"start" if k == 0 else f"t={row[0]:.2f}"}" time="{row[0]:.17g}" '
            f'qpos="{_numbers([*row[1:4], *np.zeros(feet), *row[4:8]])}"/>' for k, row in enumerate(np.asarray(keys))]


def write_mjcf(path: str | Path, scene: Scene, support: Feet, mu: float | None = None,
               start: ArrayLike | None = None, keys: ArrayLike | None = None) -> None:
    """Write :func:`mjcf` to ``path`` atomically (:func:`planner.model.files.write_atomic`)."""
    write_atomic(path, mjcf(scene, support, mu, start, keys))


def needs_mujoco() -> None:
    """Import MuJoCo, or raise :class:`SceneError` naming ``--simulate`` with :data:`MISSING`."""
    try:
        import mujoco  # noqa: F401 (only checked here)
    except ImportError:
        raise SceneError("simulate", MISSING) from None


@dataclass(frozen=True)
class Run:
    """One open-loop run of a whole plan on one foot set.

    Attributes
    ----------
    feet : Feet
    goal_error, final_error : (float, float)
        Final pose against the scene's goal and against the plan's final pose: distance of the
        slider frame's origin (m) and wrapped angle (rad).
    deviation : float
        Largest distance (m) of the part's CF from its planned position over the samples.
    slip : float
        Largest distance (m) the pusher's face midpoint moved in the part frame during a push,
        from where it was when the push began (slip along the edge, or separation).
    collisions : int
        Samples at which the part touched a wall or an obstacle.
    in_goal : bool
        The final pose is within the scene's tolerance.
    seconds, simulated : float
        Wall time of the run and simulated time, s.
    poses : (n, 3) ndarray
        The part's simulated pose at each trajectory sample.
    segment_deviation, segment_slip : tuple of float
        ``deviation`` and ``slip`` of each plan segment alone (slip 0 on a transit), so that a
        failure can be traced to the push or transit where it began.
    """

    feet: Feet
    goal_error: tuple[float, float]
    final_error: tuple[float, float]
    deviation: float
    slip: float
    collisions: int
    in_goal: bool
    seconds: float
    simulated: float
    poses: np.ndarray
    segment_deviation: tuple[float, ...]
    segment_slip: tuple[float, ...]

    @property
    def passed(self) -> bool:
        return self.in_goal and self.slip <= SLIP and not self.collisions

    def line(self, k: int, n: int) -> str:
        faults = ([] if self.in_goal else ["misses the goal"]) + (["SLIPS"] if self.slip > SLIP else []) + (
            [f"collides ({self.collisions} samples)"] if self.collisions else [])
        return (f"simulate {k}/{n} ({self.feet.kind}, {len(self.feet.points)} feet): goal error "
                f"{self.goal_error[0]:.2e} m, {self.goal_error[1]:.2e} rad; from the plan's end "
                f"{self.final_error[0]:.2e} m, {self.final_error[1]:.2e} rad; path deviation {self.deviation:.2e} m"
                f"{_where(self.segment_deviation)}; slip {self.slip:.2e} m{_where(self.segment_slip)}; "
                f"{self.seconds:.1f} s for {self.simulated:.1f} s: "
                f"{', '.join(faults) if faults else 'ok'}")


def _where(by_segment: tuple[float, ...]) -> str:
    """`` (segment k)``: the plan segment (from 1) where a per-segment measure is largest."""
    return f" (segment {int(np.argmax(by_segment)) + 1})" if len(by_segment) > 1 and max(by_segment) > 0 else ""


class Runs:
    """What every batch of simulated runs reports (``runs``, each with ``passed`` and
    ``line(k, n)``): whether all passed, and a line per run, numbered from 1."""

    runs: tuple

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.runs)

    def lines(self) -> list[str]:
        return [r.line(k, len(self.runs)) for k, r in enumerate(self.runs, 1)]


@dataclass(frozen=True)
class Simulation(Runs):
    """Outcome of :func:`simulate`: one :class:`Run` per foot set, and the trajectory they followed."""

    runs: tuple[Run, ...]
    mu: float
    motion: Trajectory
    start: np.ndarray  # where the part is placed: the plan's start, moved by any start error
    planned: np.ndarray  # the planned part pose at each of motion's samples

    #: Seconds between the keyframes :meth:`write_mjcf` writes along the run.
    KEY_EVERY = 1.0

    @property
    def worst(self) -> Run:
        """The run that strays farthest from the planned path (the first of equals)."""
        return max(self.runs, key=lambda r: r.deviation)

    def write_mjcf(self, path: str | Path, scene: Scene) -> None:
        """Write the first run's model (:func:`mjcf`) to ``path`` atomically, with keyframes of the
        planned part and the pusher every :attr:`KEY_EVERY` s of the trajectory and at its end
        (MuJoCo's viewer steps through them)."""
        m = self.motion
        rows = np.unique(np.append(np.searchsorted(m.t, np.arange(0.0, m.duration, self.KEY_EVERY)), len(m.t) - 1))
        keys = np.column_stack([m.t, self.planned, m.x, m.y, m.z, np.unwrap(m.theta)])[rows]
        write_mjcf(path, scene, self.runs[0].feet, self.mu, self.start, keys)

    def summary(self) -> str:
        worst = max(r.goal_error[0] for r in self.runs)
        return (f"simulate: {'passed' if self.passed else 'FAILED'}: {sum(r.passed for r in self.runs)}/{len(self.runs)} "
                f"runs in the goal without slip or collision (MuJoCo, pusher mu {self.mu:g}, table mu {TABLE_MU:g}); "
                f"worst goal error {worst:.2e} m, worst slip {max(r.slip for r in self.runs):.2e} m, "
                f"{sum(r.seconds for r in self.runs):.1f} s")


class World:
    """One run's MuJoCo model and data: the part placed at ``start``, the pusher driven by a
    function of the run's clock ``u`` (seconds since the pusher began to move, after
    :data:`SETTLE`), and the bumps ``(T, dx, dy, dtheta)`` applied when ``u`` passes ``T``."""

    def __init__(self, scene: Scene, support: Feet, mu: float | None, start: np.ndarray, bumps: tuple = ()):
        import mujoco  # only when simulating: a plan run without --simulate never loads it

        self.mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_string(mjcf(scene, support, mu, start))
        self.data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.model.key("start").id)
        self.own = {self.model.geom(f"part{j}").id for j in range(len(convex_pieces(scene.slider.polygon)))}
        self.part = self.model.joint("part_x").qposadr[0] + np.arange(3)
        self.part_speed = self.model.joint("part_x").dofadr[0] + np.arange(3)
        self.blocks = {self.model.geom(i).id for i in range(self.model.ngeom)
                       if self.model.geom(i).name.startswith(("wall", "obstacle"))}
        self.qpos = self.model.joint("pusher_x").qposadr[0] + np.arange(4)
        self.qvel = self.model.joint("pusher_x").dofadr[0] + np.arange(4)
        self.bumps = sorted(bumps)
        self.outline = scene.slider.polygon
        self.pusher = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth))

    def step_to(self, t: float, pusher) -> None:
        """Step to ``t`` (MuJoCo's clock), the pusher set before every step to ``pusher(u)``:
        ``(x, y, z, theta)`` and their rates; at rest before ``u = 0``."""
        data = self.data
        while data.time < t - TIMESTEP / 2:
            u = data.time - SETTLE
            pose, rate = pusher(max(u, 0.0))
            data.qpos[self.qpos] = pose
            data.qvel[self.qvel] = rate if u >= 0 else 0.0
            while self.bumps and self.bumps[0][0] <= u:
                # A knock: the part is where it was moved to, at rest, and not into the pusher,
                # which is rigid: a knock towards it leaves the part against its face.
                data.qpos[self.part] = self._off_pusher(data.qpos[self.part] + self.bumps.pop(0)[1:], pose)
                data.qvel[self.part_speed] = 0.0
            self.mujoco.mj_step(self.model, data)

    def _off_pusher(self, part: np.ndarray, pusher: ArrayLike) -> np.ndarray:
        """``part`` moved along the pusher's +x, by :data:`BUMP_STEP` steps, until it is off the
        pusher's body at ``pusher`` (``x, y, z, theta``); as it is if the pusher is lifted."""
        x, y, z, theta = pusher
        body = slider_at(self.pusher, [x, y, theta])
        along = np.array([math.cos(theta), math.sin(theta), 0.0])
        moved = part.copy()
        while z < THICKNESS and slider_at(self.outline, moved).intersects(body) and np.linalg.norm(moved - part) < 0.1:
            moved = moved + BUMP_STEP * along
        return moved

    def pose(self) -> np.ndarray:
        return self.data.qpos[self.part].copy()

    def colliding(self) -> bool:
        """The part touches a wall or an obstacle."""
        return any(c.dist < 0 and ({c.geom1, c.geom2} & self.blocks) and ({c.geom1, c.geom2} & self.own)
                   for c in self.data.contact[:self.data.ncon])


def _follower(motion: Trajectory):
    """``u -> (pusher qpos, qvel)`` along ``motion`` (linear interpolation between its samples)."""
    path = np.column_stack([motion.x, motion.y, motion.z, np.unwrap(motion.theta)])
    speed = np.column_stack([motion.vx, motion.vy, np.gradient(motion.z, motion.t) if len(motion.t) > 1
                             else np.zeros(1), motion.omega])

    def at(u: float) -> tuple[list[float], list[float]]:
        return ([np.interp(u, motion.t, column) for column in path.T],
                [np.interp(u, motion.t, column) for column in speed.T])

    return at


def _run(scene: Scene, plan: Plan, motion: Trajectory, planned: np.ndarray, support: Feet, mu: float | None,
         start: np.ndarray, lead: Trajectory, bumps: tuple) -> Run:
    clock = time.perf_counter()
    world = World(scene, support, mu, start, bumps)
    led, follow = _follower(lead), _follower(motion)

    def pusher(u: float):
        return led(u) if u < lead.duration else follow(u - lead.duration)

    times = motion.t + SETTLE + lead.duration
    poses = np.empty((len(times), 3))
    collisions = 0
    slips, starts = np.zeros(len(plan.segments)), {}
    world.step_to(SETTLE + lead.duration, pusher)
    for row, t in enumerate(times):
        world.step_to(t, pusher)
        poses[row] = world.pose()
        collisions += world.colliding()
        if motion.contact[row]:
            # The face midpoint in the part frame, against where it was when this push began.
            face = relative_pose(poses[row], [motion.x[row], motion.y[row], motion.theta[row]])[:2]
            k = int(motion.segment[row])
            first = starts.setdefault(k, face)
            slips[k] = max(slips[k], float(np.linalg.norm(face - first)))
    cf = scene.slider.cf[None]
    gap = np.linalg.norm(np.array([transform_points(cf, p)[0] for p in poses])
                         - np.array([transform_points(cf, p)[0] for p in planned]), axis=1)
    by_segment = [motion.segment == k for k in range(len(plan.segments))]
    end = poses[-1]
    deviations = tuple(float(gap[rows].max(initial=0.0)) for rows in by_segment)
    return Run(support, _error(end, scene.goal), _error(end, plan.final), float(gap.max()),
               float(slips.max(initial=0.0)), collisions, scene.within_tolerance(end), time.perf_counter() - clock,
               float(motion.duration + lead.duration), poses, deviations, tuple(float(v) for v in slips))


def _error(end: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    return math.hypot(end[0] - target[0], end[1] - target[1]), abs(float(wrap_angle(end[2] - target[2])))


def _lead_in(scene: Scene, plan: Plan, model: CollisionModel) -> Trajectory:
    """The pusher's move from :func:`.approach.lead_in_pose` to the plan's first contact."""
    edge = first_edge(plan)
    contact = edge_contact_pose(scene.slider, edge, plan.start)
    path = np.array([lead_in_pose(scene, model, plan), contact])
    step = float(np.linalg.norm(path[1, :2] - path[0, :2]))
    return trajectory(scene, Plan.of_part(scene.part().name, plan.start, plan.start, [Transit(edge, edge, "plane", path, step, np.asarray(plan.start, dtype=float))],
                                          scene=None, solved=True, planner=plan.planner, seed=plan.seed, planning_time_s=0.0))


def perturbations(scene: Scene, plan: Plan, model: CollisionModel, start_error: ArrayLike = (0.0, 0.0, 0.0),
                  bumps: ArrayLike = (), noise: ArrayLike = (0.0, 0.0)) -> tuple[np.ndarray, tuple, Trajectory,
                                                                                 Trajectory]:
    """Check a run's perturbations against ``plan`` and return the part's actual start, the bumps
    as ``(T, dx, dy, dtheta)`` tuples in time order, the lead-in and the plan's trajectory.

    ``start_error`` ``(dx, dy, dtheta)`` (m, m, rad, world frame) moves the part off the plan's
    start; each bump ``(T, dx, dy, dtheta)`` displaces it at ``T`` seconds after the pusher
    begins to move (its lead-in included) by that much; ``noise`` ``(sigma_m, sigma_rad)`` is on
    what a closed loop observes.

    Raises
    ------
    SceneError
        Naming ``start_error``, ``bump`` (and which, if several) or ``pose_noise``: a value not finite, negative noise, a
        bump time outside the run, a perturbed part outside the workspace, on an obstacle or (at
        the start) on the pusher.
    """
    error = np.asarray(start_error, dtype=float)
    if error.shape != (3,) or not np.isfinite(error).all():
        raise SceneError("start_error", f"must be three finite numbers (dx, dy, dtheta), got {np.ravel(error).tolist()}")
    sigma = np.asarray(noise, dtype=float)
    if sigma.shape != (2,) or not np.isfinite(sigma).all() or (sigma < 0).any():
        raise SceneError("pose_noise", f"must be two finite standard deviations >= 0, got {np.ravel(sigma).tolist()}")
    start = np.asarray(plan.start, dtype=float) + error
    start[2] = wrap_angle(start[2])
    fault = placement_fault(scene.slider, scene.obstacles, scene.workspace, start)
    lead = _lead_in(scene, plan, model)
    pusher = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth))
    if fault is None and slider_at(pusher, [lead.x[0], lead.y[0], lead.theta[0]]).intersects(
            slider_at(scene.slider.polygon, start)):
        fault = "the part is on the pusher where it starts"
    if fault:
        raise SceneError("start_error", f"puts the part where it cannot be: {fault}")
    motion = trajectory(scene, plan)
    planned = planned_part(scene, plan, motion)
    rows = np.asarray(bumps, dtype=float).reshape(-1, 4) if len(bumps) else np.zeros((0, 4))
    out = []
    for k, (t, dx, dy, dtheta) in enumerate(rows):
        name, which = "bump", f"bump {k + 1}: " if len(rows) > 1 else ""
        if not np.isfinite(rows[k]).all():
            raise SceneError(name, f"{which}must be four finite numbers (T, dx, dy, dtheta), got {rows[k].tolist()}")
        if not 0 <= t <= lead.duration + motion.duration:
            raise SceneError(name, f"{which}time {t:g} s is outside the run (0 to {lead.duration + motion.duration:.2f} s)")
        at = planned[min(int(np.searchsorted(motion.t, t - lead.duration)), len(planned) - 1)] if t > lead.duration \
            else start
        moved = at + [dx, dy, dtheta]
        if (fault := placement_fault(scene.slider, scene.obstacles, scene.workspace, moved)) is not None:
            raise SceneError(name, f"{which}puts the part where it cannot be (where the plan has it at {t:g} s): {fault}")
        out.append((float(t), float(dx), float(dy), float(dtheta)))
    return start, tuple(sorted(out)), lead, motion


def simulate(scene: Scene, plan: Plan, n: int = 3, seed: int = 1, mu: float | None = None,
             cf_offset: ArrayLike = (0.0, 0.0), start_error: ArrayLike = (0.0, 0.0, 0.0),
             bumps: ArrayLike = ()) -> Simulation:
    """Run ``plan`` open-loop in MuJoCo once per foot set of :func:`feet` (module docstring).

    Parameters
    ----------
    scene, plan : Scene, Plan
        The scene and a plan for it (solved or loaded).
    n : int
        Number of support distributions, >= 1.
    seed : int
        Seed of the random foot sets.
    mu : float, optional
        Pusher-part friction to simulate with; default the planned ``scene.pusher.mu``.
    cf_offset : (2,) array_like
        Moves the support's centre of pressure from the CF, slider frame (m).
    start_error, bumps : array_like
        The part's start off the plan's, and knocks during the run (:func:`perturbations`).

    Every run begins with the pusher behind the first contact, moving in (:func:`.approach.lead_in_pose`).

    Returns
    -------
    Simulation

    Raises
    ------
    SceneError
        If MuJoCo is missing (:data:`MISSING`), the offset centre is off the part, or a
        perturbation is bad (:func:`perturbations`).
    """
    needs_mujoco()
    supports = feet(scene, n, seed, cf_offset)
    start, knocks, lead, motion = perturbations(scene, plan, CollisionModel(scene, scene.edges), start_error,
                                                bumps)
    planned = planned_part(scene, plan, motion)
    return Simulation(tuple(_run(scene, plan, motion, planned, s, mu, start, lead, knocks) for s in supports),
                      scene.pusher.mu if mu is None else mu, motion, start, planned)
