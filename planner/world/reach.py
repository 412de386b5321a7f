"""Where a scene's arm can hold the pusher on the table: its reach zone (:class:`ReachZone`).

A plan for an arm must keep the pusher where the arm can hold it, flange down, at every instant,
and must not wind the arm's last joint past its stop. Both are made conditions on the pusher
frame's table pose alone, so the planner checks them as it checks obstacles, by a clearance:

* **The ring.** The arm's kinematics is the same about its first joint's axis at every angle of
  that joint, so the pusher positions it reaches with the flange down at the push height form a
  ring about the base: radii ``inner`` to ``outer``. :func:`reach_zone` finds them on the arm's
  *planar family* of postures, the ready posture's with only its three bending joints moved (the
  Panda's 2, 4 and 6, the UR5e's 2, 3 and 4; the third set so that the flange points straight
  down), over a fine grid of the first two: where the pusher's height crosses the push height,
  every joint within its limits and every joint frame past the first at least a link's radius
  above the table. That is a posture the arm has, so the ring is inside the true reach; it is
  then shrunk by :data:`RING_MARGIN` each side, room for the inverse kinematics to converge.
* **The wrist.** Measure the pusher's heading against the direction from the base to the pusher
  (``psi``: zero when pushing straight away from the base, where the mount puts the last joint
  at the middle of its range, :mod:`planner.arm.reach`). As the pusher turns, the last joint turns
  with it, nearly one for one, so a last joint of less than a full turn (the Panda's +-2.8973 rad)
  bounds how far ``psi`` can go either way from zero before the wrist meets its stop. Keeping
  ``|psi|`` within a bound below 180 degrees at every pose of a plan keeps the wrist from winding
  past its stop on any continuous motion, on the table or in the air: ``psi`` cannot go round
  without crossing the band about pushing straight at the base, where the plan changes edge or
  lifts instead. The bound is the wrist's reach as the arm's inverse kinematics
  (:mod:`planner.arm.reach`) measures it, less :data:`WRIST_MARGIN`: its other joints take up
  some of the turn, more the nearer the pusher is to the base (:data:`WRIST`: 175 degrees up to
  0.50 m from a Panda's base, 174.5 at 0.70 m, 166.5 at its outer rim). The UR5e's last joint turns two
  whole turns: its bound is the cap, 180 degrees less the margin, which keeps its wrist within
  half a turn of where a path starts it.

:meth:`ReachZone.clearance` is a lower bound on how far the pusher's body must move (in the
collision model's metric: a point's speed plus the body's reach times its turn rate) before it
leaves the zone, so conservative advancement (:func:`planner.world.validity.advances`) treats the
zone's rim as it treats an obstacle's.

The Panda with a 0.12 m tool pushing 0.01 m above the table reaches farthest with its elbow
bent until its two offset links line up (0.3266 m and 0.3928 m, 0.7194 m from the shoulder to the
wrist's centre), the wrist's centre 0.096 m below the shoulder (0.333 - 0.01 - 0.12 - 0.107) and
the flange 0.088 m beyond it: sqrt(0.7194^2 - 0.096^2) + 0.088 = 0.801 m, less the margin. Its
wrist turns the pusher to 180 degrees from pushing straight away (its other joints help its last,
which turns +-166 degrees) up to half a metre out, and 171.5 degrees at 0.78 m; less the margin:

>>> from planner.model.robot import Robot
>>> zone = reach_zone(Robot("panda", np.array([0.0, 0.0, 0.0]), 0.12))
>>> round(zone.outer + RING_MARGIN, 3), round(math.degrees(zone.bound(0.5)), 1), round(math.degrees(zone.bound(0.78)), 1)
(0.801, 175.0, 166.5)
>>> zone.holds((0.5, 0.0, 0.0)), zone.holds((0.5, 0.0, math.pi)), zone.holds((0.1, 0.0, 0.0))
(True, False, False)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..model.arms import ARMS, Arm
from ..model.robot import Robot

__all__ = ["RING_MARGIN", "WRIST", "WRIST_MARGIN", "ReachZone", "family_posture", "reach_zone"]

#: How far inside the planar family's ring (m) the zone's rims are.
RING_MARGIN = 0.02
#: How far inside the wrist's measured reach (rad, 5 degrees) the zone's bound on ``|psi|`` is.
WRIST_MARGIN = math.radians(5.0)
#: Per arm, how far ``|psi|`` turns from zero before
#: the wrist comes within 0.05 rad of its stop, following the inverse kinematics from pushing
#: straight away at ``(distance from the base (m), degrees)``, the lesser of the two ways (the
#: Panda with a 0.12 m tool: 189.0 at 0.50 m, 179.5 at 0.70 m, 176.2 at 0.74 m, 171.5 at 0.78 m;
#: docs/arm.md). Between these points it is interpolated, held at the ends, and never above 180.
WRIST = {"panda": ((0.50, 189.0), (0.70, 179.5), (0.74, 176.2), (0.78, 171.5)),
         # The UR5e's last joint turns two whole turns: the cap. A random scene's plan that took
         # the pusher round the base near its inner rim turned it 270 degrees on one edge.
         "ur5e": ((0.0, 360.0),)}
_GRID = 181  # samples of each of the two bending joints gridded (a step of about 1 degree)
#: How far from a distance asked for (m) family_posture looks for the posture nearest the ready
#: one: a grid step moves the pusher up to about 1.2 cm, and with 5 mm the nearest crossings of
#: the UR5e's elbow-up postures were sometimes all too far, leaving an elbow-down one 7 cm up.
NEAR = 0.02
_PLANAR = {"panda": (1, 3, 5), "ur5e": (1, 2, 3)}  # the bending joints (from 0) of the planar family


@dataclass(frozen=True)
class ReachZone:
    """Where the pusher frame may be (module docstring): ``inner`` to ``outer`` (m) from
    ``centre``, the base's ``(x, y)``; with ``wrist`` ``(distances (m), bounds (rad))``, the
    bound on ``|psi|`` at those distances from the base, interpolated between them (None: no
    bound)."""

    centre: tuple[float, float]
    inner: float
    outer: float
    wrist: tuple[tuple[float, ...], tuple[float, ...]] | None = None
    #: The lowest the arm's links come above the table (m), and where they reach on the table's
    #: plane: within ``spread`` (m) of the segment from ``back`` behind the base to ``ahead``
    #: beyond the pusher, on the line through both (:meth:`shadow`). Only an obstacle taller
    #: than ``floor`` can meet the arm, and only there.
    floor: float = math.inf
    back: float = 0.0
    ahead: float = 0.0
    spread: float = 0.0

    def shadow(self, x: float, y: float) -> tuple[tuple[float, float], tuple[float, float]]:
        """The ends of the segment whose ``spread`` holds the arm on the table's plane, the pusher
        frame at ``(x, y)``; its ends move at most :meth:`shadow_rate` times as fast as the pusher.

        >>> ReachZone((0.0, 0.0), 0.2, 0.8, back=0.1, ahead=0.05).shadow(0.5, 0.0)
        ((-0.1, 0.0), (0.55, 0.0))
        """
        dx, dy = x - self.centre[0], y - self.centre[1]
        rho = math.hypot(dx, dy)
        ux, uy = dx / rho, dy / rho
        return ((self.centre[0] - self.back * ux, self.centre[1] - self.back * uy),
                (x + self.ahead * ux, y + self.ahead * uy))

    @property
    def shadow_rate(self) -> float:
        """How many times as fast as the pusher the ends of :meth:`shadow` move at most: the
        direction from the base turns at most at the pusher's speed over ``inner``."""
        return 1.0 + max(self.back, self.ahead) / self.inner

    def bound(self, rho: float) -> float:
        """The bound on ``|psi|`` (rad) at ``rho`` (m) from the base; infinite without one.

        >>> zone = ReachZone((0.0, 0.0), 0.2, 0.8, ((0.5, 0.7), (3.0, 2.8)))
        >>> zone.bound(0.3), zone.bound(0.6), zone.bound(0.9)
        (3.0, 2.9, 2.8)
        """
        return math.inf if self.wrist is None else float(np.interp(rho, *self.wrist))

    def clearance(self, pose, turn: float) -> float:
        """A lower bound on how far a body holding the pusher frame at ``pose`` must move
        before the pusher leaves the zone, where each metre its points move turns it at most
        ``turn`` radians (2 over its diameter); <= 0 outside.

        >>> zone = ReachZone((0.0, 0.0), 0.2, 0.8, ((0.5,), (math.radians(150),)))
        >>> round(zone.clearance((0.75, 0.0, 0.0), 10.0), 9), round(zone.clearance((0.0, 0.9, math.pi / 2), 10.0), 9)
        (0.05, -0.1)

        Turned 140 degrees, 10 from the bound, which the turn (10 rad a metre) and the pusher's
        going round the base (1/0.2 rad a metre at the inner rim) use up within 0.175 / 15 m:

        >>> round(zone.clearance((0.5, 0.0, math.radians(140)), 10.0), 5)
        0.01164
        """
        x, y, heading = pose
        dx, dy = float(x) - self.centre[0], float(y) - self.centre[1]
        rho = math.hypot(dx, dy)
        ring = min(rho - self.inner, self.outer - rho)
        if self.wrist is None or ring <= 0:
            return ring
        psi = math.remainder(float(heading) - math.atan2(dy, dx), 2 * math.pi)
        # psi turns with the body and as the pusher goes round the base (at most 1 / rho per
        # metre); the bound changes with rho at most at its steepest slope per metre.
        return min(ring, (self.bound(rho) - abs(psi)) / (turn + 1.0 / self.inner + self._slope))

    @functools.cached_property
    def _slope(self) -> float:
        rho, bound = self.wrist
        return float(np.abs(np.diff(bound) / np.diff(rho)).max(initial=0.0))

    def holds(self, pose) -> bool:
        """Whether the pusher frame at ``pose`` is in the zone."""
        return self.clearance(pose, 1.0) > 0

    def text(self) -> str:
        """The zone in words.

        >>> ReachZone((0.0, 0.0), 0.3, 0.78, ((0.5, 0.78), (3.05, 2.85))).text()
        '0.30 to 0.78 m from its base, the pusher turned at most 163 to 175 degrees from pushing straight away from it'
        """
        ring = f"{self.inner:.2f} to {self.outer:.2f} m from its base"
        if self.wrist is None:
            return ring
        low, high = (round(math.degrees(f(self.wrist[1]))) for f in (min, max))
        most = f"{low}" if low == high else f"{low} to {high}"
        return f"{ring}, the pusher turned at most {most} degrees from pushing straight away from it"


def _chain(arm: Arm, q: np.ndarray) -> list[np.ndarray]:
    """Every joint frame's transform (batched, ``(n, 4, 4)``) then the flange's, base frame at the origin."""
    n = len(q)
    pose = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    frames = []
    for k, (a, d, alpha) in enumerate(arm.dh):
        c, s = np.cos(q[:, k]), np.sin(q[:, k])
        ca, sa = math.cos(alpha), math.sin(alpha)
        step = np.zeros((n, 4, 4))
        step[:, 3, 3] = 1.0
        if arm.convention == "modified":  # Rx(alpha) Tx(a) Rz(q) Tz(d)
            step[:, 0, :] = np.c_[c, -s, np.zeros(n), np.full(n, a)]
            step[:, 1, :] = np.c_[ca * s, ca * c, np.full(n, -sa), np.full(n, -sa * d)]
            step[:, 2, :] = np.c_[sa * s, sa * c, np.full(n, ca), np.full(n, ca * d)]
        else:  # Rz(q) Tz(d) Tx(a) Rx(alpha)
            step[:, 0, :] = np.c_[c, -s * ca, s * sa, a * c]
            step[:, 1, :] = np.c_[s, c * ca, -c * sa, a * s]
            step[:, 2, :] = np.c_[np.zeros(n), np.full(n, sa), np.full(n, ca), np.full(n, d)]
        pose = pose @ step
        frames.append(pose)
    flange = pose.copy()
    flange[:, :3, 3] += arm.flange * pose[:, :3, 2]
    return frames + [flange]


def _down_tilt(flange: np.ndarray) -> np.ndarray:
    """The flange z axis's angle from straight down in the arm's plane (x, z at joint 1 zero)."""
    return np.arctan2(flange[:, 0, 2], -flange[:, 2, 2])


@functools.lru_cache(maxsize=16)
def _family(model: str, tool_length: float, push_height: float) -> tuple[np.ndarray, np.ndarray]:
    """Postures of the planar family (module docstring) holding the pusher at the push height,
    joint 1 at zero: the pusher's distances from the base axis ``(m,)`` and the postures ``(m, n)``
    (none where the family never reaches the table)."""
    arm = ARMS[model]
    a, b, c = _PLANAR[model]
    lower, upper = np.array(arm.lower), np.array(arm.upper)
    qa, qb = np.meshgrid(np.linspace(lower[a], upper[a], _GRID), np.linspace(lower[b], upper[b], _GRID), indexing="ij")
    q = np.tile(np.array(arm.ready, dtype=float), (qa.size, 1))
    q[:, a], q[:, b], q[:, c] = qa.ravel(), qb.ravel(), 0.0
    tilt = _down_tilt(_chain(arm, q)[-1])
    probe = q[:1].copy()
    probe[0, c] = 0.1
    sign = np.sign((_down_tilt(_chain(arm, probe)[-1]) - tilt[:1])[0])  # the third joint tilts the flange one for one
    base = -tilt / sign
    # The turn that brings the flange down, or that plus a whole turn, whichever is within limits
    # (nearest the ready posture's where both are).
    choices = np.stack([base + k * 2 * math.pi for k in (-2, -1, 0, 1, 2)])
    allowed = (choices >= lower[c]) & (choices <= upper[c])
    cost = np.where(allowed, np.abs(choices - arm.ready[c]), np.inf)
    q[:, c] = choices[np.argmin(cost, axis=0), np.arange(qa.size)]
    ok = np.isfinite(cost.min(axis=0))
    chain = _chain(arm, q)
    flange = chain[-1]
    pusher = flange[:, :3, 3] + tool_length * flange[:, :3, 2]
    ok &= np.abs(flange[:, 2, 2] + 1.0) < 1e-9
    ok &= np.min([f[:, 2, 3] for f in chain[1:]], axis=0) >= arm.radius
    shape = (*qa.shape, len(arm.dh))
    height, rho, ok, q = (pusher[:, 2] - push_height).reshape(qa.shape), np.hypot(pusher[:, 0], pusher[:, 1]).reshape(qa.shape), ok.reshape(qa.shape), q.reshape(shape)
    radii, postures = [], []
    for h, r, good, joints in ((height, rho, ok, q), (height.T, rho.T, ok.T, q.transpose(1, 0, 2))):
        # Between neighbours on either side of the push height, both postures allowed.
        cross = (np.sign(h[:, :-1]) != np.sign(h[:, 1:])) & good[:, :-1] & good[:, 1:]
        w = h[:, :-1][cross] / (h[:, :-1][cross] - h[:, 1:][cross])
        radii.append(r[:, :-1][cross] + w * (r[:, 1:][cross] - r[:, :-1][cross]))
        postures.append(joints[:, :-1][cross] + w[:, None] * (joints[:, 1:][cross] - joints[:, :-1][cross]))
    return np.concatenate(radii), np.concatenate(postures)


def _footprint(arm: Arm, postures: np.ndarray, tool_length: float) -> tuple[float, float, float, float]:
    """Where ``arm``'s link capsules are over ``postures`` (joint 1 at zero): their lowest point
    above the table, and on the table's plane how far behind the base and beyond the pusher
    their joint frames go along the line through both, and how far from that line, plus a
    capsule's radius (a capsule lies between two frames, and a distance to a segment is convex):
    ``(floor, back, ahead, spread)`` (m)."""
    chain = _chain(arm, postures)
    flange = chain[-1]
    pusher = flange[:, :2, 3] + tool_length * flange[:, :2, 2]
    points = np.stack([f[:, :3, 3] for f in chain[1:]], axis=1)  # (postures, frames, 3)
    radii = np.r_[np.full(len(chain) - 2, arm.radius), 0.8 * arm.radius]  # the flange's capsule is thinner
    floor = float((points[:, :, 2] - radii).min())
    rho = np.linalg.norm(pusher, axis=1)
    u = pusher / rho[:, None]
    along = np.einsum("pfk,pk->pf", points[:, :, :2], u)  # m from the base towards the pusher
    across = np.abs(points[:, :, 0] * u[:, None, 1] - points[:, :, 1] * u[:, None, 0])
    back = float(np.maximum(-along, 0.0).max())
    ahead = float(np.maximum(along - rho[:, None], 0.0).max())
    return floor, back, ahead, float((across + radii).max())


def family_posture(robot: Robot, rho: float) -> np.ndarray:
    """A posture of ``robot``'s planar family holding the pusher at the push height about ``rho``
    (m) from the base axis (the nearest it has), joint 1 at zero: of those within :data:`NEAR` of
    the nearest, the one nearest the ready posture. Where the arm's inverse kinematics starts a path.

    >>> from planner.model.robot import Robot
    >>> q = family_posture(Robot("panda", np.zeros(3), 0.12), 0.5)
    >>> q.round(2).tolist()[::2]  # joints 1, 3, 5 and 7 as the ready posture has them
    [0.0, 0.0, 0.0, 0.79]
    """
    radii, postures = _family(robot.model, float(robot.tool_length), float(robot.push_height))
    if not radii.size:
        return np.array(ARMS[robot.model].ready, dtype=float)
    gap = np.abs(radii - rho)
    near = gap <= gap.min() + NEAR
    return postures[near][np.argmin(np.linalg.norm(postures[near] - ARMS[robot.model].ready, axis=1))].copy()


def reach_zone(robot: Robot) -> ReachZone:
    """The reach zone of ``robot`` (module docstring); empty (``inner > outer``) where the planar
    family never holds the pusher at the push height."""
    radii, postures = _family(robot.model, float(robot.tool_length), float(robot.push_height))
    if not radii.size:
        return ReachZone((float(robot.base[0]), float(robot.base[1])), math.inf, -math.inf)
    wrist = None
    if robot.model in WRIST:
        rho, degrees = zip(*WRIST[robot.model])
        wrist = (rho, tuple(min(math.pi, math.radians(d)) - WRIST_MARGIN for d in degrees))
    # The postures the arm takes (family_posture's, every centimetre of the zone's ring), not
    # every one of the family: some fold the elbow low or behind the base, where the arm does not go.
    inner, outer = float(radii.min()) + RING_MARGIN, float(radii.max()) - RING_MARGIN
    taken = np.array([family_posture(robot, rho) for rho in np.linspace(inner, outer, max(2, int((outer - inner) / 0.01)))])
    return ReachZone((float(robot.base[0]), float(robot.base[1])), inner, outer, wrist, *_footprint(ARMS[robot.model], taken, float(robot.tool_length)))
