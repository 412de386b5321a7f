"""Near-shortest pushing paths: Dubins curves of an edge's car, as chains of stable pushes.

Each edge's stable pushes contain a Dubins car (:mod:`planner.actions.car`): its centre of friction goes
straight or turns left or right at radius ``R``, and every such motion is a stable push. Dubins
curves are the shortest paths of that car (Lynch & Mason 1996 cite them for a forward-only car);
OMPL's :class:`ompl.base.DubinsStateSpace` gives them. A curve is checked by conservative
advancement (a body point moves at most ``1 + reach / R`` times the CF's speed, so from clearance
``d`` the CF may travel ``d / (1 + reach / R)``: thin obstacles are not skipped), cut back into
its (at most three) constant-curvature pieces (:func:`pieces`), and each piece is one push,
re-checked for stability and collisions like any push. :class:`DubinsShortcut` uses them to
shorten plans.
"""
from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob

from mechanics import wrap_angle

from .car import EdgeCar, edge_car
from .controls import EdgeControls
from ..model.segments import Push, append_push, rechain
from ..model.scene import Scene
from ..world.validity import CollisionModel, advances
from .push import free_push
from .shortcut import farthest_first

__all__ = ["WHOLE_PLAN_CARS", "DubinsCurves", "DubinsShortcut", "pieces"]

#: Starting intervals per turning radius of curve length when cutting a curve into pieces (the
#: halving finds every joint; this only bounds its depth), and the most of them: a curve of a metre
#: turning at a micron (a part of microns) would otherwise be sampled millions of times.
_SAMPLES_PER_RADIUS, _MOST_SAMPLES = 4, 4096
#: Least relative gain for which a shortcut replaces a stretch of plan: its pieces are pushes
#: too, and a push is not worth adding for less.
_GAIN = 0.01
#: Most edges' cars a curve for a whole plan may take (:meth:`DubinsShortcut.whole_plan_edges`):
#: more than any shipped part has.
WHOLE_PLAN_CARS = 16


def pieces(curve, length: float, radius: float, tol: float = 1e-12) -> list[tuple[float, float]]:
    """``(curvature, length)`` of each constant-curvature piece of a Dubins curve.

    ``curve(t)`` gives the state ``(x, y, heading)`` at the fraction ``t`` of the curve's
    ``length`` (arc length is linear in ``t``). An interval is one piece when its end follows
    from its start by one of the three motions (left, straight or right at radius ``radius``) to
    within ``tol``; otherwise it holds a joint (or several: then it matches no single motion either)
    and is halved, down to ``tol`` in length.

    >>> import numpy as np
    >>> def turn_then_straight(t):   # left through 1 rad at R = 1, then straight: 3 m in all
    ...     s = 3.0 * t
    ...     a = min(s, 1.0)
    ...     return np.sin(a) + (s - a) * np.cos(a), 1 - np.cos(a) + (s - a) * np.sin(a), a
    >>> [(k, round(s, 9)) for k, s in pieces(turn_then_straight, 3.0, 1.0)]
    [(1.0, 1.0), (0.0, 2.0)]
    """
    out: list[list[float]] = []

    def add(kappa: float, ds: float) -> None:
        if out and out[-1][0] == kappa:
            out[-1][1] += ds
        else:
            out.append([kappa, ds])

    def split(t0: float, p0: np.ndarray, t1: float, p1: np.ndarray) -> None:
        ds = (t1 - t0) * length
        for kappa in (1.0 / radius, 0.0, -1.0 / radius):
            gap = _along(p0, kappa, ds) - p1
            if max(abs(gap[0]), abs(gap[1]), abs(float(wrap_angle(gap[2])))) <= tol:
                add(kappa, ds)
                return
        if ds <= tol:  # a joint pinned down to within tol: its sliver goes to the piece before
            if out:
                out[-1][1] += ds
            return
        tm = 0.5 * (t0 + t1)
        pm = np.asarray(curve(tm), dtype=float)
        split(t0, p0, tm, pm)
        split(tm, pm, t1, p1)

    if length <= 0:
        return []
    n = min(_MOST_SAMPLES, max(2, math.ceil(_SAMPLES_PER_RADIUS * length / radius)))
    grid = np.linspace(0.0, 1.0, n + 1)
    states = [np.asarray(curve(t), dtype=float) for t in grid]
    for k in range(n):
        split(grid[k], states[k], grid[k + 1], states[k + 1])
    return [(float(k), float(s)) for k, s in out if s > 0]


def _along(state: np.ndarray, kappa: float, ds: float) -> np.ndarray:
    """The car state after ``ds`` of arc at curvature ``kappa`` (heading wrapped to the start's branch)."""
    x, y, psi = state
    if kappa == 0.0:
        return np.array([x + ds * math.cos(psi), y + ds * math.sin(psi), psi])
    turn = kappa * ds
    return np.array([x + (math.sin(psi + turn) - math.sin(psi)) / kappa,
                     y - (math.cos(psi + turn) - math.cos(psi)) / kappa, psi + turn])


class DubinsCurves:
    """Dubins curves of one edge's car as chains of stable pushes, collision-checked.

    Parameters
    ----------
    scene : Scene
    car : EdgeCar
    model : CollisionModel, optional
        With a body for the car's edge; needed only to check curves (:meth:`is_free`, :meth:`connect`).
    margin : float
        Clearance every push keeps.

    Examples
    --------
    Lengths need no collision model. The battery's pusher, on the edge at the back, pushes the CF
    along +x, so the shortest curve to 0.2 m straight ahead is that straight line:

    >>> from planner.actions.car import edge_car
    >>> from planner.actions.controls import edge_controls
    >>> from planner.model.scene_file import load_scene
    >>> scene = load_scene("scenes/battery.yaml")
    >>> car = edge_car(edge_controls(scene)[0], scene.slider.cf)
    >>> round(DubinsCurves(scene, car).between(scene.start, scene.start + [0.2, 0.0, 0.0]), 9)
    0.2
    """

    def __init__(self, scene: Scene, car: EdgeCar, model: CollisionModel | None = None, margin: float = 0.0):
        self.car, self.model, self.margin = car, model, margin
        self.space = ob.DubinsStateSpace(car.radius)
        bounds = ob.RealVectorBounds(2)
        xmin, ymin, xmax, ymax = scene.workspace
        bounds.setLow(0, xmin), bounds.setLow(1, ymin), bounds.setHigh(0, xmax), bounds.setHigh(1, ymax)
        self.space.setBounds(bounds)
        self.bound = 1.0 + car.reach() / car.radius
        self._a, self._b, self._probe = (self.space.allocState() for _ in range(3))

    def states(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> None:
        """Load car states ``a`` and ``b`` for :meth:`length`, :meth:`is_free` and :meth:`pieces`."""
        for state, (x, y, psi) in ((self._a, a), (self._b, b)):
            state.setXY(x, y), state.setYaw(psi)

    def length(self) -> float:
        """Length of the CF's path along the Dubins curve between the loaded states."""
        return self.space.distance(self._a, self._b)

    def lengths(self, a: ArrayLike, b: ArrayLike) -> np.ndarray:
        """Dubins lengths from car states ``a`` to car states ``b`` (rows ``(x, y, psi)``): from
        one state to each of many, or from each of many to one.

        Straight ahead, and back where it started:

        >>> from planner.actions.car import edge_car
        >>> from planner.actions.controls import edge_controls
        >>> from planner.model.scene_file import load_scene
        >>> scene = load_scene("scenes/battery.yaml")
        >>> curves = DubinsCurves(scene, edge_car(edge_controls(scene)[0], scene.slider.cf))
        >>> lengths = curves.lengths([[0.0, 0.0, 0.0]], [[0.3, 0.0, 0.0], [0.0, 0.0, 0.0]])
        >>> lengths.round(9).tolist()
        [0.3, 0.0]
        """
        a, b = np.asarray(a, dtype=float).reshape(-1, 3), np.asarray(b, dtype=float).reshape(-1, 3)
        if len(a) != 1 and len(b) != 1:
            raise ValueError(f"one end must be a single state, got {len(a)} and {len(b)}")
        # The single end is set once: setting states costs more than the distance
        # (docs/stack.md, "Dubins curves").
        fixed, moving, many = (self._a, self._b, b) if len(a) == 1 else (self._b, self._a, a)
        x, y, psi = (a if len(a) == 1 else b)[0].tolist()
        fixed.setXY(x, y), fixed.setYaw(psi)
        out = np.empty(len(many))
        for i, (x, y, psi) in enumerate(many.tolist()):
            moving.setXY(x, y), moving.setYaw(psi)
            out[i] = self.space.distance(self._a, self._b)
        return out

    def blocked(self, samples: int) -> bool:
        """Whether the curve between the loaded states certainly hits something: the part's CF
        leaves the room its disk needs (:meth:`~planner.world.validity.CollisionModel.surely_blocked`)
        at one of ``samples`` points inside it. A cheap screen before :meth:`is_free`."""
        cf = np.empty((samples, 2))  # the car's reference point is the CF
        for i, t in enumerate(((np.arange(samples) + 0.5) / samples).tolist()):
            self.space.interpolate(self._a, self._b, t, self._probe)
            cf[i] = self._probe.getX(), self._probe.getY()
        return bool(self.model.cf_blocked(cf).any())

    def between(self, start: np.ndarray, goal: np.ndarray) -> float:
        """Load the car states of slider poses ``start`` and ``goal``; the :meth:`length` between them."""
        self.states(self.car.state(start), self.car.state(goal))
        return self.length()

    def is_free(self) -> bool:
        """Whether the curve between the loaded states keeps the margin, by conservative
        advancement (module docstring)."""
        def clearance(t: float) -> float:
            self.space.interpolate(self._a, self._b, t, self._probe)
            return self.model.clearance(self.car.pose(_xy_yaw(self._probe)), self.car.push.edge)

        return advances(clearance, 1.0, self.bound * self.space.distance(self._a, self._b), self.margin)

    def pieces(self) -> list[tuple[float, float]]:
        """The curve's pieces, ``(curvature, length)``, between the loaded states."""
        def along(t: float) -> tuple[float, float, float]:
            self.space.interpolate(self._a, self._b, t, self._probe)
            return _xy_yaw(self._probe)

        return pieces(along, self.length(), self.car.radius)

    def pushes(self, pose: np.ndarray, runs: list[tuple[float, float]]) -> list[Push] | None:
        """One push per piece ``(curvature, length)`` from slider ``pose``; None if one fails
        its re-check (stability, clearance) after rounding."""
        controls, out = self.car.push, []
        for kappa, length in runs:
            twist = self.car.twist(kappa)
            speed = float(controls.speed(twist))
            # No body point faster than 1 m/s.
            push = free_push(controls, self.model, self.margin, pose, twist / speed, length * speed)
            if isinstance(push, str):
                return None
            out.append(push)
            pose = push.end
        return out

    def connect(self, start: np.ndarray, goal: np.ndarray) -> list[Push] | None:
        """The pushes along the Dubins curve from slider pose ``start`` to ``goal``, if it is free."""
        self.states(self.car.state(start), self.car.state(goal))
        return self.pushes(np.asarray(start, dtype=float), self.pieces()) if self.is_free() else None


def _xy_yaw(state) -> tuple[float, float, float]:
    return state.getX(), state.getY(), state.getYaw()


class _Cars(Mapping):
    """Edge to :class:`DubinsCurves` of its car, for the edges that have one (an edge whose stable
    pushes turn neither way has none); each car is made when first asked for, since a part of many
    edges may use few of them."""

    def __init__(self, scene: Scene, controls: list[EdgeControls], model: CollisionModel, margin: float):
        self._scene, self._model, self._margin = scene, model, margin
        self._controls = {c.edge: c for c in controls}
        self._made: dict[int, DubinsCurves | None] = {}

    def _curves(self, edge: int) -> DubinsCurves | None:
        if edge not in self._made:
            car = edge_car(self._controls[edge], self._scene.slider.cf)
            self._made[edge] = None if car is None else DubinsCurves(self._scene, car, self._model, self._margin)
        return self._made[edge]

    def __getitem__(self, edge: int) -> DubinsCurves:
        if edge not in self._controls or (curves := self._curves(edge)) is None:
            raise KeyError(edge)
        return curves

    @property
    def edges(self) -> list[int]:
        """The edges that may have a car (made or not)."""
        return list(self._controls)

    def __iter__(self) -> Iterator[int]:
        return (e for e in self._controls if self._curves(e) is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)


class DubinsShortcut:
    """Shorten a plan by Dubins curves of the edges' cars wherever one is free and shorter.

    The plan's pushes are halved, and between any two of the resulting waypoints on one edge
    (no transit between them) the Dubins curve of that edge's car replaces the plan if it is
    shorter (the centre of friction's path, by at least :data:`_GAIN`) and free; greedy, farthest
    waypoint first, so the plan only gets shorter. A plan without transits may move to another
    edge's car (the first push may be on any edge).

    Parameters
    ----------
    scene : Scene
    controls : the allowed edges' controls
    model : CollisionModel
        With a body for each of those edges.
    margin : float
        Clearance every push keeps.
    """

    def __init__(self, scene: Scene, controls: list[EdgeControls], model: CollisionModel, margin: float):
        self.cf, self._slider = scene.slider.cf, scene.slider
        self.curves = _Cars(scene, controls, model, margin)

    def __call__(self, segments: list) -> list:
        out, run = [], []
        for s in [*segments, None]:
            if isinstance(s, Push):
                run += _halves(s)
                continue
            if run:
                for push in self._shorten(run, alone=s is None and not out):
                    append_push(out, push)
                run = []
            if s is not None:
                out.append(s)
        return rechain(out)

    def _shorten(self, run: list[Push], alone: bool) -> list[Push]:
        """``run`` (pushes on one edge) shortened; if it is the whole plan (``alone``), one curve
        for all of it may be on any edge's car, since the pusher may start on any edge, but a
        curve for part of it only on the run's edge: the pusher cannot change edges unseen."""
        waypoints = [s.start for s in run] + [run[-1].end]
        travelled = np.concatenate([[0.0], np.cumsum([s.cf_path_length(self.cf) for s in run])])

        def curve(i: int, j: int) -> list[Push] | None:
            edges = self.whole_plan_edges(run[0].edge) if alone and (i, j) == (0, len(run)) else [run[0].edge]
            return self._curve(waypoints[i], waypoints[j], travelled[j] - travelled[i], edges)

        return farthest_first(run, curve)

    def whole_plan_edges(self, edge: int) -> list[int]:
        """The edges whose cars a curve for a whole plan pushed on ``edge`` may take: that edge and
        the longest others, :data:`WHOLE_PLAN_CARS` in all (every edge of a part of fewer). A car costs milliseconds to make, and a
        part of a thousand edges (a circle's outline from CAD) would spend seconds on cars most of
        which turn no tighter than the rest; a longer edge holds the pusher's contact farther out
        and so tends to turn tighter."""
        slider = self._slider
        others = sorted((e for e in self.curves.edges if e != edge),
                        key=lambda e: (-float(np.linalg.norm(np.subtract(*slider.edge(e)))), e))
        chosen = {edge, *others[:WHOLE_PLAN_CARS - 1]}
        return [e for e in self.curves.edges if e in chosen]  # in the edges' order, as ever: ties go the same way

    def _curve(self, start: np.ndarray, end: np.ndarray, longest: float, edges: list[int]) -> list[Push] | None:
        """The shortest free Dubins curve among ``edges``' cars shorter than ``longest``, as pushes."""
        options = []
        for e in edges:
            curves = self.curves.get(e)
            if curves is None:
                continue
            length = curves.between(start, end)
            if length < (1.0 - _GAIN) * longest:
                options.append((length, e))
        for _, e in sorted(options):
            found = self.curves[e].connect(start, end)
            if found is not None:
                return found
        return None


def _halves(push: Push) -> list[Push]:
    """``push`` as two pushes of half its duration: its middle becomes a waypoint."""
    first = replace(push, duration=push.duration / 2).moved(push.start)
    return [first, replace(push, duration=first.duration, start=first.end)]
