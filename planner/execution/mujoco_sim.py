"""Whole plans run open-loop in MuJoCo: the pusher follows the plan's trajectory blindly.

:mod:`.verify` re-simulates each push with the quasi-static mechanics the planner assumes. Here
the plan meets a physics engine that assumes none of it: every part is a rigid body with mass on
the table, the pusher a kinematic body driven along :func:`.trajectory.trajectory` (lifted to
``z`` in a lift's flight), and every segment runs after the last with no correction. A plan of
one part and a plan of several (moves joined by transfers) take the same path: one model with
every part of the scene in it, one run loop, one report; a scene of one part is the case without
part-part contacts.

**The model** (:func:`mjcf`). A table (plane), the workspace walls and the obstacles as prisms
(non-convex ones as their :func:`~planner.model.bodies.convex_pieces`; an obstacle as tall as its
``height:``, the walls :data:`WALL_HEIGHT`), each part as one body made
of the convex pieces of its polygon (thin prisms), and the pusher as a prism of the pusher body's
outline. A part does not lie on its face: it stands on a few small spherical *feet*, each a
body of its own that slides vertically in the part and weighs its share ``w_i`` of the support
(``w_i`` the foot's weight in the distribution, :class:`Feet`), so its normal force on the table,
hence its friction, is exactly that share; the part's centre of mass is the support's centre (the
CF, or the CF moved by an offset). So each foot set is one support distribution: the barycentric
weights of three feet round the centre, or a grid's weights moved to put the centre there
(:func:`mechanics.quasistatic.grid_support`). The part itself moves in the plane only (x, y and
heading): a free part rocked on its feet under the pusher's moment about the table, and the
pusher's friction, which with a vertical face also acts vertically, carried some of its weight,
so the feet's loads, hence the distribution, were not the ones meant. Only the listed contact
pairs exist: feet-table (friction :data:`TABLE_MU`), pusher-part for every part (the planned
``scene.pusher.mu``, or ``mu=``), part-obstacle (to detect collisions) and part-part (with the
table's friction: a part shoved by another moves as it would, and the shove is seen). Each part has
a foot set of its own: run ``k`` gives every part the ``k``-th foot set :func:`feet` draws for it.

The pusher is not a mocap body: contact friction sees a mocap body's velocity as zero, so the
part's friction against a moving pusher would be computed as if it were still (the part slid
along the face by a fifth of the push). It is a heavy body on x, y, z and heading joints whose
positions and velocities are set to the trajectory before every step, so that it follows the
plan exactly, and which is pushed in that step by the force that gives it the trajectory's
acceleration: its mass matrix times the change of the trajectory's rates over the step
(:meth:`World.step_to`; the run loop applies it, the MJCF cannot say it).

**Coulomb friction.** The plan's guarantee is about Coulomb friction (a push in the exact region
sticks for every support distribution), so the model is tuned for its two states: a sticking
contact does not move, a sliding one slides at the friction limit. The trajectory is slow
(inertial forces a sixtieth of friction at most), so that is what decides where the parts go.
The numbers below are the slip of the corridor's seed-1 plan (``scenes/corridor.yaml``) over
the 8 distributions of ``--simulate 8``: its second push sticks for every distribution by the
LP of ``tests/oracle.py``, but slipped 0.9-8.2 mm, in 5 runs past 1 mm, before these choices;
with all of them no push slips more than 0.05 mm. Each one left out:

- *Gravity ten times Earth's* (:data:`GRAVITY`). The quasi-static motion does not depend on
  gravity's magnitude, since every force in it scales with it; the soft contact does. At
  Earth's gravity the sliding feet hopped: over the battery's push each foot carried nothing in
  7-10 % of the steps and up to 1.5 times its share in others, so the support distribution
  changed at every step and some of those distributions broke the push: up to 7.5 mm of slip.
  At ten times each foot's load stays within 0.4 % of its share at every step.
- *The pusher's acceleration*. Without the force above the solver saw a pusher that does not
  accelerate, and friction lagged a turning pusher: 0.09-0.12 mm.
- *The no-slip pass* (``noslip_iterations``, :data:`NOSLIP_ITERATIONS`). MuJoCo's soft friction
  has no exact sticking state: a contact well inside its cone still creeps, the slower the
  larger ``impratio`` (MuJoCo issue 3328). The no-slip pass re-solves the friction forces
  alone, as hard constraints, after each step's solve. Without it: 0.60-0.63 mm. It stops
  when it has converged: 10 iterations give the same slips to the micrometre, 20 leave a margin.
- *The pusher-part contact's time constant* (``solref``, :data:`PUSHER_TIMECONST`), twice the
  step, the stiffest MuJoCo allows. At the default 0.02 s the pusher's penetration of the part
  changes with the load on its face, which shows as slip: 0.19 mm on the first push. The feet
  keep the default time constant.

Elliptic friction cones are MuJoCo's exact Coulomb cones (pyramidal ones are linearised, and
with the no-slip pass they threw the corridor's part half a metre off its path), solved by the
Newton solver to a tolerance of 1e-10 at every step, with ``impratio`` 10, friction ten times
stiffer than the normal direction (at 1 the corridor slipped 3.4 mm even with the no-slip pass).
The step, :data:`TIMESTEP` (2 ms), is a tenth of the feet's contact time constant; 1 ms moves the
corridor's worst slip from 0.05 to 0.07 mm and parking's from 0.12 to 0.07 mm, at about twice
the cost: what creep is left is not the step's.

What remains is creep, at most 0.12 mm in a push of the shipped scenes' plans, while a push
10 % outside the exact region slips by about a millimetre or more over 6 cm on its worst
distribution (``tests/planner/execution/test_mujoco.py``); the slip threshold :data:`SLIP` is
0.2 mm.

**What is measured** (:class:`Run`), at every trajectory sample: each part's simulated pose
against its planned one (:func:`.trajectory.planned_part`: during a push of it, the pusher frame's
pose times the inverse of the contact pose; otherwise where it was left), the pusher face's
midpoint in the frame of the part it pushes while ``contact`` is 1 (it should stay where it was
when the push began: moving along the edge is slip, away from it separation; measured per push, so
that an error the part carries from earlier pushes is deviation, not slip), and the contacts that
must not happen: a part against another part, a wall or an obstacle, or the pusher against a part
other than the one it moves (or, on a transfer, leaves), so a push that shoves a second part is
caught. A run fails if any part ends outside its goal tolerance, the pusher slips or any such
contact happens. Every run begins with the pusher behind the first move's first contact, moving
in (:func:`.approach.lead_in_pose`), and may be perturbed (:func:`perturbations`).

**With a robot** (a scene's ``robot:`` block) the pusher prism is on the arm's flange and the
arm's servos follow the joint trajectory (:mod:`.arm_sim`): the same parts, contacts and checks,
slip measured at the simulated pusher from when it touches the part, and the arm's links touching
anything a fault too.
"""

from __future__ import annotations

import bisect
import importlib
import math
import time
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple, TypeVar
from xml.sax.saxutils import quoteattr

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, pose_error, relative_pose, transform_points, wrap_angle
from mechanics.quasistatic import grid_support, tripod_supports

from ..actions.transit import edge_contact_pose
from ..model.bodies import convex_pieces, pusher_frame_body, slider_at
from ..model.fields import SceneError
from ..model.files import write_atomic
from ..model.scene import Scene
from ..model.plan import Plan
from ..model.segments import Transfer, Transit
from ..model.scene_file import placement_fault
from ..world.validity import CollisionModel
from .approach import first_edge, lead_in_pose
from .trajectory import Trajectory, planned_part, trajectory

if TYPE_CHECKING:  # the arm's model needs mink: loaded only for a scene with a robot
    from ..arm.joints import JointTrajectory
    from .arm_sim import SimArm

__all__ = ["DIVERGED", "MAX_RUNS", "MISSING", "SLIP", "TABLE_MU", "TIMESTEP", "ByPart", "Feet", "Perturbed", "Run", "Runs", "Simulation", "World", "feet",
           "foot_sets", "mjcf", "needs_mujoco", "perturbations", "simulate", "support_centre", "write_mjcf"]

#: The one line ``plan --simulate`` prints (after ``plan: error: --simulate: ``) without MuJoCo.
MISSING = "needs MuJoCo: pip install 'stablepush[mujoco]'"
#: Part-table friction coefficient: the plan holds for any, so one fixed value.
TABLE_MU = 0.5
#: Integration step, s (module docstring, "Coulomb friction").
TIMESTEP = 0.002
#: Gravity, m/s^2: ten times Earth's, so that the feet stay loaded (module docstring).
GRAVITY = 98.1
#: Iterations of MuJoCo's no-slip post-pass on friction (module docstring).
NOSLIP_ITERATIONS = 20
#: Time constant of the pusher-part contacts, s: the stiffest MuJoCo allows (module docstring).
PUSHER_TIMECONST = 2 * TIMESTEP
#: Slip threshold, m: the pusher's face midpoint may move this far in the part frame while pushing.
SLIP = 0.0002
#: Part geometry: prism thickness, foot radius (m), mass (kg); obstacle and wall height (m).
THICKNESS, FOOT, MASS, WALL_HEIGHT = 0.004, 0.001, 0.1, 0.03
#: Mass of the pusher, kg: far heavier than the part, so a step's contact forces barely move it.
PUSHER_MASS = 1000.0
#: Time the parts are left to settle on their feet before the pusher moves, s.
SETTLE = 0.1
#: Feet of a grid distribution (about).
GRID_FEET = 9
#: Most runs of one simulation (each some seconds): a bound on the work a number asks for.
MAX_RUNS = 1_000
#: Step by which a knocked part is moved off the pusher, m.
BUMP_STEP = 0.0002
#: How a run that blew up is reported (World.diverged): its one fault, which fails it.
DIVERGED = "the simulation diverged"
#: The text of the last MuJoCo warning (World): one, however many a long run raises.
_LAST_WARNING: list[str] = []


def _keep_warning(text: str) -> None:
    _LAST_WARNING[:] = [text]

T = TypeVar("T")


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
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_RUNS:
        raise SceneError("simulate", f"must be 1 to {MAX_RUNS} distributions, got {n!r}")
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


def foot_sets(scene: Scene, n: int, seed: int = 1, offset: ArrayLike = (0.0, 0.0)) -> list[dict[str, Feet]]:
    """The feet of ``n`` runs, by part name: run ``k`` puts every part on the ``k``-th of its own
    :func:`feet` (``seed`` and ``offset`` as there)."""
    sets = {name: feet(scene.move_scene(name, scene.starts), n, seed, offset) for name in scene.names}
    return [{name: s[k] for name, s in sets.items()} for k in range(n)]


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


def _table(scene: Scene) -> tuple[list[str], list[str], list[str]]:
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
    for i, (obstacle, height) in enumerate(zip(scene.obstacles, scene.obstacle_heights)):
        for j, piece in enumerate(convex_pieces(obstacle)):
            name = f"obstacle{i}_{j}"
            assets.append(_prism(name, piece, 0.0, height))  # as tall as the scene has it: an arm may meet its top
            world.append(f'<geom name="{name}" type="mesh" mesh="{name}" rgba=".6 .3 .3 1"/>')
            blocks.append(name)
    return assets, world, blocks


#: Height of the pusher prism, m: above the parts.
PUSHER_TOP = THICKNESS + 2 * FOOT + 0.01


def _free_pusher() -> str:
    """The free pusher's body: the prism on x, y, z and heading joints (module docstring)."""
    return f"""<body name="pusher" gravcomp="1">
      <joint name="pusher_x" type="slide" axis="1 0 0"/>
      <joint name="pusher_y" type="slide" axis="0 1 0"/>
      <joint name="pusher_z" type="slide" axis="0 0 1"/>
      <joint name="pusher_theta" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{PUSHER_MASS}" diaginertia="{_numbers([PUSHER_MASS * 0.01] * 3)}"/>
      <geom name="pusher" type="mesh" mesh="pusher" rgba=".1 .1 .1 1"/>
    </body>"""


def _document(scene: Scene, assets: list[str], world: list[str], bodies: list[str], pairs: list[str],
              keys: list[str], arm: SimArm | None = None) -> str:
    """The MJCF document of ``scene``: the options, the table plane, ``world``'s geoms, the parts'
    ``bodies``, the pusher (a prism of its outline on x, y, z and heading joints, or on ``arm``'s
    flange, :mod:`.arm_sim`; last in the joints' order), the contact ``pairs`` and the ``keys``."""
    xmin, ymin, xmax, ymax = scene.workspace
    span = max(xmax - xmin, ymax - ymin)
    assets = assets + [_prism("pusher", pusher_frame_body(scene.pusher.width, scene.pusher.depth), 0.0, PUSHER_TOP)]
    pusher = _free_pusher() if arm is None else arm.body(PUSHER_TOP)
    step = TIMESTEP if arm is None else arm.timestep
    actuators = "" if arm is None else f"<actuator>{''.join(arm.actuators())}</actuator>"
    return f"""<mujoco model={quoteattr(scene.name)}>{"" if arm is None else '<compiler angle="radian"/>'}
  <option timestep="{step}" gravity="0 0 {-GRAVITY:g}" cone="elliptic" impratio="10" solver="Newton" iterations="50" tolerance="1e-10" noslip_iterations="{NOSLIP_ITERATIONS}"/>
  <default>
    <geom contype="0" conaffinity="0"/>{"" if arm is None else arm.defaults()}
  </default>
  <asset>
    {chr(10).join('    ' + a for a in assets).strip()}
  </asset>
  <worldbody>
    <geom name="table" type="plane" size="{_numbers([span, span, 0.1])}" pos="{_numbers([(xmin + xmax) / 2, (ymin + ymax) / 2, 0])}" rgba=".9 .9 .85 1"/>
    {chr(10).join('    ' + w for w in world).strip()}
    {chr(10).join('    ' + b for b in bodies).strip()}
    {pusher}
  </worldbody>
  <contact>
    {chr(10).join('    ' + p for p in pairs).strip()}
  </contact>{actuators}
  <keyframe>
    {chr(10).join('    ' + k for k in keys).strip()}
  </keyframe>
</mujoco>
"""


def _part_body(name: str, prefix: str, slider: Slider, support: Feet) -> tuple[list[str], str, list[str], list[str]]:
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


def _part_pairs(geoms: list[str], blocks: list[str], mu: float) -> list[str]:
    """The contacts of a part's ``geoms``: with the pusher (friction ``mu``), and with the walls
    and obstacles (``blocks``; frictionless, there only to be detected)."""
    pairs = []
    for g in geoms:
        pairs.append(f'<pair geom1="pusher" geom2="{g}" condim="3" friction="{mu} {mu} 0 0 0" '
                     f'solref="{PUSHER_TIMECONST:g} 1"/>')
        pairs += [f'<pair geom1="{b}" geom2="{g}" condim="1"/>' for b in blocks]
    return pairs


def _names(scene: Scene) -> list[tuple[str, str]]:
    """Each part's body name and the prefix of its geoms' names in the model, scene order: ``part``
    and ``part`` for the one part of a scene (geoms ``part0``..., feet ``foot0``...: the one-part
    model's names, which viewers and scripts know), ``part<k>`` and ``part<k>_`` for part ``k``
    of several (geoms ``part<k>_0``..., feet ``foot<k>_0``...); the names are the model's own, as
    the parts' may be any text."""
    if len(scene.parts) == 1:
        return [("part", "part")]
    return [(f"part{k}", f"part{k}_") for k in range(len(scene.parts))]


def mjcf(scene: Scene, supports: Mapping[str, Feet], mu: float | None = None,
         starts: Mapping[str, ArrayLike] | None = None, keys: ArrayLike | None = None,
         arm: SimArm | None = None) -> str:
    """The MuJoCo model (MJCF XML) of ``scene`` with each part on its ``supports`` feet (by part
    name), starting at ``starts`` (default: the scene's starts), and pusher-part friction ``mu``
    (default: the planned ``scene.pusher.mu``); module docstring, "The model". The bodies are
    named by :func:`_names`.

    ``keys``, rows ``(t, each part's x, y, theta in scene order, pusher x, y, z, theta)``, become
    keyframes ``t=<t>`` (the first named ``start``) so that a viewer can step along a run; without
    them the one keyframe ``start`` has the parts at ``starts`` and the pusher at the world origin.

    With ``arm`` (:mod:`.arm_sim`) the pusher is on the arm's flange, the keys end with the arm's
    joint angles instead of the pusher's pose, and ``start`` has the arm at its reference's first."""
    mu = scene.pusher.mu if mu is None else mu
    starts = scene.starts if starts is None else starts
    assets, world, blocks = _table(scene)
    tail, rest = (4, np.zeros(4)) if arm is None else (arm.count, arm.q[0])
    # The arm's tool slide (arm_sim) is the model's last joint, at rest.
    slide = () if arm is None else (0.0,)
    bodies, pairs, geoms = [], [], []
    for (name, prefix), part in zip(_names(scene), scene.parts):
        more, body, own, feet_pairs = _part_body(name, prefix, part.slider, supports[part.name])
        assets += more
        bodies.append(body)
        geoms.append(own)
        pairs += feet_pairs
    for k, own in enumerate(geoms):
        pairs += _part_pairs(own, blocks, mu)
        # Parts against parts, with the table's friction: a part shoved by another moves as it would.
        pairs += [f'<pair geom1="{g}" geom2="{h}" condim="3" friction="{TABLE_MU} {TABLE_MU} 0 0 0"/>'
                  for g in own for other in geoms[k + 1:] for h in other]
    if arm is not None:
        pairs += arm.pairs(["table", *blocks, *(g for own in geoms for g in own)])
    feet_counts = [len(supports[name].points) for name in scene.names]
    if keys is None:
        frames = [f'<key name="start" qpos="{_qpos([starts[n] for n in scene.names], feet_counts, [*rest, *slide])}"/>']
    else:
        frames = [f'<key name="{"start" if k == 0 else f"t={row[0]:.2f}"}" time="{row[0]:.17g}" '
                  f'qpos="{_qpos(np.reshape(row[1:-tail], (-1, 3)), feet_counts, [*row[-tail:], *slide])}"/>'
                  for k, row in enumerate(np.asarray(keys))]
    return _document(scene, assets, world, bodies, pairs, frames, arm)


def _qpos(poses: list[ArrayLike], feet_counts: list[int], pusher: ArrayLike) -> str:
    """A keyframe's ``qpos``: the joints in model order are each part's three and one per foot (at
    rest: 0), in scene order, then the pusher's four (or the arm's)."""
    return _numbers([*(v for pose, k in zip(poses, feet_counts) for v in (*pose, *np.zeros(k))), *pusher])


def write_mjcf(path: str | Path, scene: Scene, supports: Mapping[str, Feet], mu: float | None = None,
               starts: Mapping[str, ArrayLike] | None = None, keys: ArrayLike | None = None,
               arm: SimArm | None = None) -> None:
    """Write :func:`mjcf` to ``path`` atomically (:func:`planner.model.files.write_atomic`)."""
    write_atomic(path, mjcf(scene, supports, mu, starts, keys, arm))


def needs_mujoco() -> None:
    """Import MuJoCo, or raise :class:`SceneError` naming ``--simulate`` with :data:`MISSING`."""
    try:
        importlib.import_module("mujoco")
    except ImportError:
        raise SceneError("simulate", MISSING) from None


def _one(by_part: Mapping[str, T]) -> T:
    """The value of a run's one part; a run of several parts is asked by part name."""
    if len(by_part) != 1:
        raise SceneError("part", f"the run has {len(by_part)} parts ({', '.join(by_part)}): name one")
    return next(iter(by_part.values()))


def _worst(errors: Mapping[str, tuple[float, float]]) -> str:
    """The part whose error (distance, angle) is the largest in distance (the first of equals)."""
    return max(errors, key=lambda name: errors[name][0])


class ByPart:
    """What a run, open or closed loop, reports of each part by name (``supports``,
    ``goal_errors``, ``delivered``, ``tracks``), read as a whole: the one part's feet, the
    farthest-off part's goal error, whether every part is in its goal, the one part's poses."""

    supports: dict[str, Feet]
    goal_errors: dict[str, tuple[float, float]]
    delivered: dict[str, bool]
    tracks: dict[str, np.ndarray]

    @property
    def feet(self) -> Feet:
        return _one(self.supports)

    @property
    def goal_error(self) -> tuple[float, float]:
        return self.goal_errors[_worst(self.goal_errors)]

    @property
    def in_goal(self) -> bool:
        """Every part ends within tolerance of its goal."""
        return all(self.delivered.values())

    @property
    def poses(self) -> np.ndarray:
        return _one(self.tracks)


@dataclass(frozen=True)
class Run(ByPart):
    """One open-loop run of a whole plan, each part on one foot set of its own.

    Attributes
    ----------
    supports : dict of str to Feet
        Each part's feet, by part name.
    goal_errors, final_errors : dict of str to (float, float)
        Each part's final pose against its goal and against where the plan leaves it: distance of
        the slider frame's origin (m) and wrapped angle (rad).
    delivered : dict of str to bool
        Whether each part's final pose is within the scene's tolerance of its goal.
    deviation : float
        Largest distance (m) of a part's CF from its planned position over the samples.
    slip : float
        Largest distance (m) the pusher's face midpoint moved in the pushed part's frame during a
        push, from where it was when the push began (slip along the edge, or separation).
    collisions : int
        Samples at which a contact that must not happen was on (module docstring).
    faults : tuple of (float, str)
        Those contacts in words (``'a touches b'``, ``'a touches a wall or obstacle'``, ``'the
        pusher touches b'``), each once, with the trajectory time (s) it was first seen.
    seconds, simulated : float
        Wall time of the run and simulated time, s.
    tracks : dict of str to (n, 3) ndarray
        Each part's simulated pose at each trajectory sample.
    segment_deviation, segment_slip : tuple of float
        ``deviation`` and ``slip`` of each plan segment alone (:attr:`Plan.segments`, transfers
        included; slip 0 off a push), so that a failure can be traced to where it began.
    tracking : float or None
        With the arm (:mod:`.arm_sim`): the largest distance (m) of the pusher frame's origin from
        where the trajectory has it, over the samples; None for the free pusher, which is set there.
    arm : (n, k, 3) ndarray or None
        With the arm: the points it is drawn through at each trajectory sample (its base, joint
        frames, flange and pusher frame's origin; :meth:`World.sample`).

    ``feet`` and ``poses`` are the one part's, for a run of one part; ``goal_error`` and
    ``final_error`` the part's farthest off, for any run.
    """

    supports: dict[str, Feet]
    goal_errors: dict[str, tuple[float, float]]
    final_errors: dict[str, tuple[float, float]]
    delivered: dict[str, bool]
    deviation: float
    slip: float
    collisions: int
    faults: tuple[tuple[float, str], ...]
    seconds: float
    simulated: float
    tracks: dict[str, np.ndarray]
    segment_deviation: tuple[float, ...]
    segment_slip: tuple[float, ...]
    tracking: float | None = None
    arm: np.ndarray | None = None

    @property
    def final_error(self) -> tuple[float, float]:
        return self.final_errors[_worst(self.final_errors)]

    @property
    def passed(self) -> bool:
        return self.in_goal and self.slip <= SLIP and not self.collisions

    def line(self, k: int, n: int) -> str:
        """The run's line, numbered ``k`` of ``n``; with several parts it names the parts its
        errors are of, the parts that miss their goals and the first few contacts that must not happen."""
        several = len(self.supports) > 1
        arm = self.tracking is not None

        def of(name: str) -> str:
            return f" ({name})" if several else ""

        missed = ", ".join(name for name, ok in self.delivered.items() if not ok)
        touches = "; ".join(f"{what} at {t:.1f} s" for t, what in self.faults[:3]) + (
            f"; {len(self.faults) - 3} more" if len(self.faults) > 3 else "")
        blown = [what for _, what in self.faults if what.startswith(DIVERGED)]
        faults = blown[:1] or ([] if self.in_goal else [f"misses the goal{': ' + missed if several else ''}"]) + (
            ["SLIPS"] if self.slip > SLIP else []) + (
            [f"collides ({self.collisions} samples{': ' + touches if several or arm else ''})"] if self.collisions else [])
        kinds = ", ".join(sorted({f.kind for f in self.supports.values()}))
        goal, final = _worst(self.goal_errors), _worst(self.final_errors)
        return (f"simulate {k}/{n} ({kinds}, {'+'.join(str(len(f.points)) for f in self.supports.values())} feet): "
                f"goal error {self.goal_error[0]:.2e} m, {self.goal_error[1]:.2e} rad{of(goal)}; from the plan's end "
                f"{self.final_error[0]:.2e} m, {self.final_error[1]:.2e} rad{of(final)}; path deviation "
                f"{self.deviation:.2e} m{_where(self.segment_deviation)}; slip {self.slip:.2e} m"
                f"{_where(self.segment_slip)}; "
                f"{f'pusher tracking {self.tracking * 1e3:.2f} mm (the arm); ' if arm else ''}"
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
    starts: dict[str, np.ndarray]  # where the parts are placed: the plan's starts, the first moved by any start error
    planned: dict[str, np.ndarray]  # each part's planned pose at each of motion's samples
    arm: SimArm | None = None  # the arm that held the pusher (arm_sim), for a scene with a robot

    #: Seconds between the keyframes :meth:`write_mjcf` writes along the run.
    KEY_EVERY = 1.0

    @property
    def worst(self) -> Run:
        """The run that strays farthest from the planned path (the first of equals)."""
        return max(self.runs, key=lambda r: r.deviation)

    def write_mjcf(self, path: str | Path, scene: Scene) -> None:
        """Write the first run's model (:func:`mjcf`) to ``path`` atomically, with keyframes of the
        planned parts and the pusher every :attr:`KEY_EVERY` s of the trajectory and at its end
        (MuJoCo's viewer steps through them); with the arm, its model and its joint angles."""
        m = self.motion
        rows = np.unique(np.append(np.searchsorted(m.t, np.arange(0.0, m.duration, self.KEY_EVERY)), len(m.t) - 1))
        pusher = [m.x, m.y, m.z, np.unwrap(m.theta)] if self.arm is None else list(self.arm.joints.q.T)
        keys = np.column_stack([m.t, *(self.planned[n] for n in scene.names), *pusher])[rows]
        write_mjcf(path, scene, self.runs[0].supports, self.mu, self.starts, keys, self.arm)

    def summary(self) -> str:
        parts = len(self.starts)
        delivered = min(sum(r.delivered.values()) for r in self.runs)
        return (f"simulate: {'passed' if self.passed else 'FAILED'}: {sum(r.passed for r in self.runs)}/{len(self.runs)} "
                f"runs {'with every part in its goal,' if parts > 1 else 'in the goal'} without slip or collision "
                f"(MuJoCo, pusher mu {self.mu:g}, table mu {TABLE_MU:g}); "
                f"{f'at least {delivered}/{parts} parts delivered in every run; ' if parts > 1 else ''}"
                f"worst goal error {max(r.goal_error[0] for r in self.runs):.2e} m, "
                f"worst slip {max(r.slip for r in self.runs):.2e} m, "
                f"{'' if self.arm is None else f'pusher held by the {self.arm.robot.model} arm, worst tracking {max(r.tracking for r in self.runs) * 1e3:.2f} mm, '}"
                f"{sum(r.seconds for r in self.runs):.1f} s")


#: The pusher as a function of a run's clock: ``u -> ((x, y, z, theta), their rates)``; or, with
#: the arm, its joints' reference: ``u -> (angles, rates)``.
Driver = Callable[[float], tuple[ArrayLike, ArrayLike]]


class World:
    """One run's MuJoCo model and data: the parts placed at ``starts`` (by name) on their
    ``supports``, the pusher driven by a function of the run's clock ``u`` (seconds since the
    pusher began to move, after :data:`SETTLE`), and the bumps ``(T, part, dx, dy, dtheta)``
    applied to that part when ``u`` passes ``T``.

    A state MuJoCo finds non-finite or huge (it then resets the data and warns) ends the run's
    physics: :attr:`diverged` says why and when, :meth:`faults` reports it from then on and
    :meth:`step_to` steps no more, so a run that blows up fails at once instead of passing on the
    reset state or stepping on for ever."""

    def __init__(self, scene: Scene, supports: Mapping[str, Feet], mu: float | None,
                 starts: Mapping[str, ArrayLike], bumps: tuple = (), arm: SimArm | None = None):
        import mujoco  # only when simulating: a plan run without --simulate never loads it

        # MuJoCo prints its warnings on the terminal, thousands a second from a run that keeps
        # blowing up; the run reports divergence itself (diverged), so they are kept, not printed.
        mujoco.set_mju_user_warning(_keep_warning)
        self.diverged: str | None = None
        # The warnings of a state MuJoCo had to reset.
        self.unstable = [int(w) for w in (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                                          mujoco.mjtWarning.mjWARN_BADQACC)]
        self.mujoco = mujoco
        self.scene, self.arm = scene, arm
        #: The model as MJCF (a renderer's copy of it adds a camera: :mod:`.depth_camera`).
        self.xml = mjcf(scene, supports, mu, starts, arm=arm)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.model.key("start").id)
        names = list(zip(_names(scene), scene.parts))
        self.slots = {part.name: self.model.joint(f"{body}_x").qposadr[0] + np.arange(3) for (body, _), part in names}
        self.speeds = {part.name: self.model.joint(f"{body}_x").dofadr[0] + np.arange(3) for (body, _), part in names}
        self.owner = {self.model.geom(f"{prefix}{j}").id: part.name for (_, prefix), part in names
                      for j in range(len(convex_pieces(part.slider.polygon)))}
        self.owned = np.isin(np.arange(self.model.ngeom), list(self.owner))  # by geom id: a part's geom
        self.blocks = {self.model.geom(i).id for i in range(self.model.ngeom)
                       if self.model.geom(i).name.startswith(("wall", "obstacle"))}
        self.pusher_geom = self.model.geom("pusher").id
        self._hold()
        self.bumps = sorted(bumps)
        self.pusher = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth))

    def _hold(self) -> None:
        """Find what drives the pusher: its joints' positions and velocities, or the arm's site,
        bodies and link geoms."""
        model, arm = self.model, self.arm
        if arm is not None:
            self.site, self.flange = model.site("pusher").id, model.site("flange").id
            self.link_ids = {model.geom(name).id: link for name, link in arm.links.items()}
            self.table = model.geom("table").id
            # The arm's bodies, last in the model and a chain: in order from its base to its flange,
            # the tool's slide after them.
            self.bodies = list(range(model.body("base").id, model.body("tool").id))
            return
        self.qpos = self.model.joint("pusher_x").qposadr[0] + np.arange(4)
        self.qvel = self.model.joint("pusher_x").dofadr[0] + np.arange(4)
        # The pusher's acceleration (zero off its dofs) and the force that gives it: _actuate's.
        self.accel, self.force = np.zeros(self.model.nv), np.zeros(self.model.nv)

    def step_to(self, t: float, pusher: Driver) -> None:
        """Step to ``t`` (MuJoCo's clock), the pusher driven before every step by ``pusher(u)``
        (:meth:`_actuate`), at rest before ``u = 0``."""
        data = self.data
        self._ahead = None
        step = self.model.opt.timestep  # the free pusher's TIMESTEP, or the arm's (arm_sim)
        while data.time < t - step / 2 and self.diverged is None:
            u = data.time - SETTLE
            pose = self._actuate(pusher, u)
            while self.bumps and self.bumps[0][0] <= u:
                # A knock: the part is where it was moved to, at rest, and not into the pusher,
                # which is rigid: a knock towards it leaves the part against its face.
                _, name, *shift = self.bumps.pop(0)
                data.qpos[self.slots[name]] = self._off_pusher(name, data.qpos[self.slots[name]] + shift, pose)
                data.qvel[self.speeds[name]] = 0.0
            self.mujoco.mj_step(self.model, data)
            if any(data.warning[w].number for w in self.unstable) or not np.isfinite(data.qpos).all():
                said = _LAST_WARNING.pop().split(". ")[0] if _LAST_WARNING else "a non-finite state"
                self.diverged = f"{DIVERGED} at {max(u, 0.0):.2f} s (MuJoCo: {said})"

    def _actuate(self, pusher: Driver, u: float) -> ArrayLike:
        """Set the pusher to ``pusher(u)``: ``(x, y, z, theta)`` and their rates; and push it by
        the force that gives it, by the step's end, the rates ``pusher`` has then (module
        docstring, "The model"). Returns its pose. With the arm, ``pusher(u)`` is the joints'
        reference angles and rates, given to its servos (:mod:`.arm_sim`)."""
        data = self.data
        if self.arm is not None:
            q, qd = self._drive(pusher, u)
            data.ctrl[:] = self.arm.controls(np.asarray(q), qd)
            return self.pusher_now()
        pose, rate = self._ahead if self._ahead is not None else self._drive(pusher, u)
        self._ahead = self._drive(pusher, u + TIMESTEP)
        data.qpos[self.qpos] = pose
        data.qvel[self.qvel] = rate
        self.accel[self.qvel] = (np.asarray(self._ahead[1]) - rate) / TIMESTEP
        self.mujoco.mj_mulM(self.model, data, self.force, self.accel)
        data.qfrc_applied[self.qvel] = self.force[self.qvel]
        return pose

    @staticmethod
    def _drive(pusher: Driver, u: float) -> tuple[ArrayLike, np.ndarray]:
        """``pusher(u)``, at rest before ``u = 0``."""
        pose, rate = pusher(max(u, 0.0))
        return pose, np.asarray(rate, dtype=float) if u >= 0 else np.zeros(np.shape(rate))

    def pusher_pose(self, planned: ArrayLike) -> ArrayLike:
        """The pusher's ``(x, y, theta)`` at a trajectory sample where the trajectory has it at
        ``planned``: there, for the free pusher, which is set to the trajectory; where the arm
        holds it."""
        return planned if self.arm is None else self.pusher_now()[[0, 1, 3]]

    def pusher_now(self) -> np.ndarray:
        """The pusher's ``(x, y, z, theta)`` as the arm holds it: its frame's origin, its height
        above ``push_height`` and its heading."""
        data = self.data
        x, y, z = data.site_xpos[self.site]
        axes = data.site_xmat[self.site].reshape(3, 3)
        heading = math.atan2(axes[1, 0], axes[0, 0]) + self.arm.mount
        return np.array([x, y, z - self.arm.robot.push_height, math.remainder(heading, 2 * math.pi)])

    def touches(self, name: str) -> bool:
        """Whether the pusher touches part ``name`` now."""
        contacts = self.data.contact
        pairs = contacts.geom[(contacts.dist < 0) & (contacts.geom == self.pusher_geom).any(axis=1)]
        return any(self.owner.get(g) == name for g in pairs.ravel())

    def sample(self, planned: ArrayLike) -> tuple[float, np.ndarray]:
        """With the arm: how far (m) the pusher frame's origin is from ``planned`` ``(x, y, z)``
        (the trajectory's sample), and the points the arm is drawn through: its bodies' origins
        from the base on, the flange and the pusher frame's origin."""
        data = self.data
        x, y, z = planned
        at = data.site_xpos[self.site]
        points = np.vstack([data.xpos[self.bodies], data.site_xpos[self.flange], at])
        return float(np.linalg.norm(at - [x, y, self.arm.robot.push_height + z])), points

    def _off_pusher(self, name: str, part: np.ndarray, pusher: ArrayLike) -> np.ndarray:
        """Part ``name`` at ``part`` moved along the pusher's +x, by :data:`BUMP_STEP` steps, until
        it is off the pusher's body at ``pusher`` (``x, y, z, theta``); as it is if the pusher is lifted."""
        x, y, z, theta = pusher
        body = slider_at(self.pusher, [x, y, theta])
        outline = self.scene.part(name).slider.polygon
        along = np.array([math.cos(theta), math.sin(theta), 0.0])
        moved = part.copy()
        while z < THICKNESS and slider_at(outline, moved).intersects(body) and np.linalg.norm(moved - part) < 0.1:
            moved = moved + BUMP_STEP * along
        return moved

    def pose(self, name: str | None = None) -> np.ndarray:
        """Part ``name``'s pose (default: the scene's one part's)."""
        return self.data.qpos[self.slots[self.scene.part(name).name]].copy()

    def faults(self, allowed: Collection[str]) -> list[str]:
        """The contacts on now that must not happen, in words: a part against another part, a wall
        or an obstacle, the pusher against a part not named in ``allowed``, or an arm's link
        against anything."""
        out = [self.diverged] if self.diverged else []
        contacts = self.data.contact
        # The feet always press into the table: only a touching pair with a part's geom is looked at.
        pairs = contacts.geom[contacts.dist < 0]
        for pair in map(set, pairs[self.owned[pairs].any(axis=1)].tolist()):
            touched = sorted({self.owner[g] for g in pair if g in self.owner})
            if len(touched) == 2:
                out.append(f"{touched[0]} touches {touched[1]}")
            elif touched and pair & self.blocks:
                out.append(f"{touched[0]} touches a wall or obstacle")
            elif touched and self.pusher_geom in pair and touched[0] not in allowed:
                out.append(f"the pusher touches {touched[0]}")
        return out if self.arm is None else out + self._link_faults(pairs)

    def _link_faults(self, pairs: np.ndarray) -> list[str]:
        """The arm's links touching anything among the touching geom ``pairs``: ``the arm's link4
        touches the table`` (or ``a wall or obstacle``, or a part by name)."""
        out = []
        for a, b in pairs[np.isin(pairs, list(self.link_ids)).any(axis=1)].tolist():
            link, other = (a, b) if a in self.link_ids else (b, a)
            what = ("the table" if other == self.table else self.owner[other] if other in self.owner
                    else "a wall or obstacle")
            out.append(f"the arm's {self.link_ids[link]} touches {what}")
        return out


def _follower(motion: Trajectory) -> Driver:
    """``u -> (pusher qpos, qvel)`` along ``motion`` (linear interpolation between its samples,
    held at the ends)."""
    table = np.column_stack([motion.x, motion.y, motion.z, np.unwrap(motion.theta), motion.vx, motion.vy,
                             np.gradient(motion.z, motion.t) if len(motion.t) > 1 else np.zeros(1), motion.omega])
    return _table_driver(motion.t, table, 4)


def _table_driver(t: ArrayLike, table: np.ndarray, split: int) -> Driver:
    """``u -> (row[:split], row[split:])`` of ``table``'s rows at times ``t``, linear between
    them, held at the ends."""
    times = np.asarray(t, dtype=float).tolist()

    def at(u: float) -> tuple[np.ndarray, np.ndarray]:
        # Called once or twice a step (World.step_to): one bisection for every column, not one each.
        k = bisect.bisect_right(times, u)
        if k == 0 or k == len(times):
            row = table[min(k, len(times) - 1)]
        else:
            row = table[k - 1] + (u - times[k - 1]) / (times[k] - times[k - 1]) * (table[k] - table[k - 1])
        return row[:split], row[split:]

    return at


class Perturbed(NamedTuple):
    """A run's set-up (:func:`perturbations`): where the parts start, the bumps ``(T, part, dx, dy,
    dtheta)`` in time order, the pusher's lead-in, the plan's trajectory and each part's planned
    pose at its samples."""

    starts: dict[str, np.ndarray]
    bumps: tuple[tuple[float, str, float, float, float], ...]
    lead: Trajectory
    motion: Trajectory
    planned: dict[str, np.ndarray]


def _run(scene: Scene, plan: Plan, setup: Perturbed, supports: dict[str, Feet], mu: float | None,
         arm: SimArm | None = None) -> Run:
    clock = time.perf_counter()
    lead, motion = setup.lead, setup.motion
    if arm is None:
        world = World(scene, supports, mu, setup.starts, setup.bumps)
        led, follow = _follower(lead), _follower(motion)

        def pusher(u: float) -> tuple[list[float], list[float]]:
            return led(u) if u < lead.duration else follow(u - lead.duration)
    else:  # the arm's joints follow their reference (World._actuate)
        world = World(scene, supports, mu, setup.starts, setup.bumps, arm)
        pusher = _table_driver(arm.t, np.hstack([arm.q, arm.qd]), arm.count)

    steps = plan.steps
    # The pusher may touch the part of its segment, and on a transfer the part it leaves: a transit
    # or a transfer begins (and ends) in contact.
    allowed = [{name, s.from_part} if isinstance(s, Transfer) else {name} for name, s in steps]
    times = motion.t + SETTLE + lead.duration
    tracks = {name: np.empty((len(times), 3)) for name in scene.names}
    collisions, faults, seen = 0, [], set()
    slips, firsts = np.zeros(len(steps)), {}
    tracking, drawn = np.zeros(len(times)), []
    world.step_to(SETTLE + lead.duration, pusher)
    for row, t in enumerate(times):
        world.step_to(t, pusher)
        for name, track in tracks.items():
            track[row] = world.pose(name)
        k = int(motion.segment[row])
        now = world.faults(allowed[k])
        collisions += bool(now)
        for fault in now:
            if fault not in seen:
                seen.add(fault)
                faults.append((float(motion.t[row]), fault))
        if arm is not None:
            tracking[row], points = world.sample([motion.x[row], motion.y[row], motion.z[row]])
            drawn.append(points)
        # With the arm, from the first sample the pusher touches the part: a servo lags, and the gap
        # it closes as the push begins is not slip.
        if motion.contact[row] and (arm is None or world.touches(steps[k][0])):
            # The face midpoint in the pushed part's frame, against where it was when this push began.
            face = relative_pose(tracks[steps[k][0]][row],
                                 world.pusher_pose([motion.x[row], motion.y[row], motion.theta[row]]))[:2]
            first = firsts.setdefault(k, face)
            slips[k] = max(slips[k], float(np.linalg.norm(face - first)))
    gap = np.max([_cf_gap(scene.part(name).slider.cf, track, setup.planned[name]) for name, track in tracks.items()],
                 axis=0)
    deviations = tuple(float(gap[motion.segment == k].max(initial=0.0)) for k in range(len(steps)))
    ends = {name: track[-1] for name, track in tracks.items()}
    return Run(dict(supports), {name: pose_error(end, scene.part(name).goal) for name, end in ends.items()},
               {name: pose_error(end, plan.finals[name]) for name, end in ends.items()},
               {name: scene.delivered(name, end) for name, end in ends.items()}, float(gap.max()),
               float(slips.max(initial=0.0)), collisions, tuple(faults), time.perf_counter() - clock,
               float(motion.duration + lead.duration), tracks, deviations, tuple(float(v) for v in slips),
               None if arm is None else float(tracking.max()), None if arm is None else np.array(drawn))


def _cf_gap(cf: np.ndarray, poses: np.ndarray, planned: np.ndarray) -> np.ndarray:
    """The distance of the CF (part frame) at each of ``poses`` from where it is at ``planned``'s."""
    return np.linalg.norm(transform_points(cf, poses) - transform_points(cf, planned), axis=1)


def _first_move(scene: Scene, plan: Plan) -> tuple[Scene, Plan]:
    """The plan's first move as the plan of its one part, in the scene of moving it (the other
    parts obstacles where they start; the scene itself for a scene of one part)."""
    return scene.move_scene(plan.moves[0].part, plan.starts), plan.move_plan()


def _lead_in(scene: Scene, plan: Plan, model: CollisionModel) -> Trajectory:
    """The pusher's move from :func:`.approach.lead_in_pose` to the first contact of ``plan``, a
    plan of ``scene``'s one part."""
    edge = first_edge(plan)
    contact = edge_contact_pose(scene.slider, edge, plan.start)
    path = np.array([lead_in_pose(scene, model, plan), contact])
    step = float(np.linalg.norm(path[1, :2] - path[0, :2]))
    return trajectory(scene, Plan.of_part(plan.part, plan.start, plan.start, [Transit(edge, edge, "plane", path, step, np.asarray(plan.start, dtype=float))],
                                          scene=None, solved=True, planner=plan.planner, seed=plan.seed, planning_time_s=0.0))


def perturbations(scene: Scene, plan: Plan, model: CollisionModel | None = None,
                  start_error: ArrayLike = (0.0, 0.0, 0.0), bumps: ArrayLike = (),
                  noise: ArrayLike = (0.0, 0.0), motion: Trajectory | None = None) -> Perturbed:
    """Check a run's perturbations against ``plan`` and set the run up (:class:`Perturbed`).

    ``start_error`` ``(dx, dy, dtheta)`` (m, m, rad, world frame) moves the first part the plan
    moves off its start; each bump ``(T, dx, dy, dtheta)`` displaces the part the pusher is on
    ``T`` seconds after it begins to move (its lead-in included: the first moved part; on a
    transfer, the part it goes to) by that much; ``noise`` ``(sigma_m, sigma_rad)`` is on what a
    closed loop observes. ``model`` is the collision model of the first move's scene (the
    scene's own for a scene of one part; default: built here), which the lead-in avoids.
    ``motion`` is the plan's trajectory (default: :func:`.trajectory.trajectory`'s; an arm's is
    timed for its joints, :mod:`.arm_timing`).

    Raises
    ------
    SceneError
        Naming ``start_error``, ``bump`` (and which, if several) or ``pose_noise``: a value not finite, negative noise, a
        bump time outside the run, a perturbed part outside the workspace, on an obstacle or
        another part, or (at the start) on the pusher.
    """
    error = np.asarray(start_error, dtype=float)
    if error.shape != (3,) or not np.isfinite(error).all():
        raise SceneError("start_error", f"must be three finite numbers (dx, dy, dtheta), got {np.ravel(error).tolist()}")
    sigma = np.asarray(noise, dtype=float)
    if sigma.shape != (2,) or not np.isfinite(sigma).all() or (sigma < 0).any():
        raise SceneError("pose_noise", f"must be two finite standard deviations >= 0, got {np.ravel(sigma).tolist()}")
    moving, lone = _first_move(scene, plan)
    start = np.asarray(lone.start, dtype=float) + error
    start[2] = wrap_angle(start[2])
    fault = placement_fault(moving.slider, moving.obstacles, moving.workspace, start)
    lead = _lead_in(moving, lone, CollisionModel(moving, moving.edges) if model is None else model)
    pusher = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth))
    if fault is None and slider_at(pusher, [lead.x[0], lead.y[0], lead.theta[0]]).intersects(
            slider_at(moving.slider.polygon, start)):
        fault = "the part is on the pusher where it starts"
    if fault:
        raise SceneError("start_error", f"puts the part where it cannot be: {fault}")
    starts = {**{name: np.asarray(pose, dtype=float) for name, pose in plan.starts.items()}, lone.part: start}
    motion = trajectory(scene, plan) if motion is None else motion
    planned = {name: planned_part(scene, plan, motion, name) for name in scene.names}
    rows = np.asarray(bumps, dtype=float).reshape(-1, 4) if len(bumps) else np.zeros((0, 4))
    out = []
    for k, (t, dx, dy, dtheta) in enumerate(rows):
        name, which = "bump", f"bump {k + 1}: " if len(rows) > 1 else ""
        if not np.isfinite(rows[k]).all():
            raise SceneError(name, f"{which}must be four finite numbers (T, dx, dy, dtheta), got {rows[k].tolist()}")
        if not 0 <= t <= lead.duration + motion.duration:
            raise SceneError(name, f"{which}time {t:g} s is outside the run (0 to {lead.duration + motion.duration:.2f} s)")
        if t > lead.duration:
            row = min(int(np.searchsorted(motion.t, t - lead.duration)), len(motion.t) - 1)
            part, poses = plan.steps[int(motion.segment[row])][0], {n: pose[row] for n, pose in planned.items()}
        else:
            part, poses = lone.part, starts
        knocked = scene.move_scene(part, poses)
        if (fault := placement_fault(knocked.slider, knocked.obstacles, knocked.workspace,
                                     poses[part] + [dx, dy, dtheta])) is not None:
            raise SceneError(name, f"{which}puts the part where it cannot be (where the plan has it at {t:g} s): {fault}")
        out.append((float(t), part, float(dx), float(dy), float(dtheta)))
    return Perturbed(starts, tuple(sorted(out)), lead, motion, planned)


def simulate(scene: Scene, plan: Plan, n: int = 3, seed: int = 1, mu: float | None = None,
             cf_offset: ArrayLike = (0.0, 0.0), start_error: ArrayLike = (0.0, 0.0, 0.0),
             bumps: ArrayLike = (), arm: tuple[Trajectory, JointTrajectory] | None = None) -> Simulation:
    """Run ``plan``, of one part or several, open-loop in MuJoCo once per foot set: run ``k`` puts
    every part on the ``k``-th of its own :func:`feet` (module docstring).

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
        Moves every support's centre of pressure from its part's CF, slider frame (m).
    start_error, bumps : array_like
        The first moved part's start off the plan's, and knocks during the run (:func:`perturbations`).
    arm : (Trajectory, JointTrajectory), optional
        For a scene with a robot, whose arm holds the pusher (:mod:`.arm_sim`): the plan's
        trajectory and the joint trajectory its servos follow along it; default
        :func:`.arm_timing.arm_trajectory`'s (timed for the arm's joints).

    Every run begins with the pusher behind the first contact, moving in (:func:`.approach.lead_in_pose`).

    Returns
    -------
    Simulation

    Raises
    ------
    SceneError
        If MuJoCo is missing (:data:`MISSING`), an offset centre is off its part, or a
        perturbation is bad (:func:`perturbations`).
    """
    needs_mujoco()
    sets = foot_sets(scene, n, seed, cf_offset)
    held = None
    if scene.robot is not None:
        from .arm_sim import sim_arm  # loads mink: only for an arm
        from .arm_timing import arm_trajectory

        motion, joints = arm_trajectory(scene, plan) if arm is None else arm
        setup = perturbations(scene, plan, None, start_error, bumps, motion=motion)
        held = sim_arm(scene.robot, setup.lead, setup.motion, joints)
    else:
        setup = perturbations(scene, plan, None, start_error, bumps)
    runs = tuple(_run(scene, plan, setup, supports, mu, held) for supports in sets)
    return Simulation(runs, scene.pusher.mu if mu is None else mu, setup.motion, setup.starts, setup.planned, held)
