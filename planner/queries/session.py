"""A planning session: one scene set up once, then many plans, re-plans and reachability queries.

As OMPL's ``SimpleSetup`` owns a space, a validity checker and a planner and solves many times,
a :class:`Planner` owns what every query on one scene shares: the edges' stable regions (read
from the region cache or computed), the collision model, the transits between edges, the
shortcuts, the certificates' free space. Each query then pays only for its own search.

A session also remembers what its queries found. :meth:`Planner.plan` with ``reuse`` (the
default) first tries to join a new start to a plan it found before for the same goal, by one or
two stable pushes (and a switch where the edges differ) onto a pose along that plan: a robot
re-planning from where the part really is gets an answer in milliseconds. Such a plan depends on
what the session planned before; ``reuse=False`` gives the plan the seed alone decides, as the
one-shot :func:`plan` (a fresh session) does.

>>> from planner import Planner, load_scene
>>> session = Planner(load_scene("scenes/battery.yaml"))
>>> first = session.plan()
>>> first.solved, first.contents()
(True, '1 push')
>>> again = session.plan(start=session.scene.start + [0.002, 0.0, 0.0])
>>> again.solved, bool(session.scene.within_tolerance(again.final))
(True, True)
>>> [a.status for a in session.reachability([session.scene.goal, [9.0, 9.0, 0.0]])]
['reachable', 'unreachable']
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..actions.controls import NoStablePush, RegionTimeout, clearance_margin
from ..actions.region_cache import RegionCache
from ..actions.transit import TransitPlanner
from ..model.fields import SceneError, integer, pose, poses
from ..model.options import PlannerOptions, check_planner
from ..model.scene import Scene
from ..model.plan import Plan
from ..search import PlanningContext, PlanRequest, SearchWorld, solve
from ..search.context import plan_result
from ..search.join import join
from ..search.transfer import TransferPaths
from ..world.validity import CollisionModel
from .memory import Memory
from .multi_part import plan_parts
from .reachability import Certificates, Reach, answers
from .reachable_set import ReachableSet, reachable_set

__all__ = ["MAX_GOALS", "Planner", "REACH_BASE_S", "REACH_PER_GOAL_S", "REMEMBERED_GOALS", "REMEMBERED_PLANS", "plan",
           "reachability", "session_options"]

#: Without a time limit, :meth:`Planner.reachability` grows its search for this long plus this
#: much per goal left open by the certificates (at most the options' time limit): on the shipped
#: scenes nearly every reachable goal of a 200-goal grid is reached well within it
#: (``python -m planner.bench.reach``).
REACH_BASE_S, REACH_PER_GOAL_S = 0.5, 0.01
#: Plans a session keeps for re-planning (the most recent), and move sessions of a scene of several parts.
REMEMBERED_PLANS = 16
#: Goals reached by reachability queries whose plans a session keeps (the most recent), for the
#: queries after them.
REMEMBERED_GOALS = 20_000
#: Most goals one reachability query takes: every goal holds its answer (a plan, for one reached)
#: until the query returns, so a larger batch is refused, not run out of memory: ask in batches.
MAX_GOALS = 100_000


class Planner:
    """A planning session on ``scene``: set up once, asked many times.

    Parameters
    ----------
    scene : Scene
    options : PlannerOptions or mapping, optional
        How to plan (:func:`session_options`): a :class:`~planner.model.options.PlannerOptions`
        in place of the scene's own (:attr:`~planner.model.scene.Scene.options`, what its file
        asks for); a mapping of option names to values (``{"seed": 3, "transit": "lift"}``)
        changes only those of the scene's. ``regions``, ``switch_cost`` and ``transit`` shape the
        session itself; ``seed``, ``time_limit``, ``optimize`` and ``name`` are each query's
        defaults, and a query may give its own. The session keeps them as :attr:`options` and
        passes them down; :attr:`scene` is the scene given.
    cache : RegionCache, optional
        Where the stable regions are kept (default: the process's, in ``$STABLEPUSH_CACHE``).
    progress : callable, optional
        ``progress(k, n)`` before computing the ``k``-th of the ``n`` regions not cached.

    A scene of several parts is planned as a whole: :meth:`plan` searches the order of moves
    (:mod:`planner.queries.multi_part`), each move planned by a session of one part among the
    others where they stand (made once and kept, :meth:`move_session`).

    Setting up computes the regions within half the options' time limit; edges not done by then
    are left out (``note`` says which), and a session with none plans nothing (each plan says why).

    Raises
    ------
    SceneError
        If an option is invalid, or the pusher has no room at the scene's start.
    """

    def __init__(self, scene: Scene, options: PlannerOptions | Mapping[str, Any] | None = None, *,
                 cache: RegionCache | None = None, progress: Callable[[int, int], None] | None = None):
        #: When setting the session up began (``time.perf_counter()``).
        self.clock = time.perf_counter()
        if not isinstance(scene, Scene):
            raise SceneError("scene", f"must be a Scene (planner.load_scene), got {type(scene).__name__}")
        #: The options the session plans with, resolved once (:func:`session_options`).
        self.options = session_options(scene, options)
        #: The scene given: its own options are only the defaults of :attr:`options`.
        self.scene = scene
        self._cache, self._progress = cache, progress
        #: A scene of one part's collision model (the part and the pusher on each allowed edge), the
        #: certificates of unreachability and the search's world (regions, transits, shortcuts);
        #: None for a scene of several parts, whose moves' sessions hold their own.
        self.model: CollisionModel | None = None
        self.certificates: Certificates | None = None
        self.world: SearchWorld | None = None
        self._no_push: NoStablePush | None = None
        self._timeout = ""
        # What the queries found, for the queries after them: plans per goal, the goals reached per
        # start (their segments), and the sessions of a scene of several parts' moves.
        self._plans, self._reached, self._moves = Memory(REMEMBERED_PLANS), Memory(REMEMBERED_GOALS), Memory(REMEMBERED_PLANS)
        self._filings = itertools.count()
        #: A scene of several parts' transfers between parts (None for one part).
        self.paths: TransferPaths | None = None
        #: Seconds the last :meth:`reachability` spent on the certificates, the direct connections
        #: and the tree's growth.
        self.timings: dict[str, float] = {}
        if len(self.scene.parts) > 1:
            # Each move is set up when the search first asks for it: only the transfers' free space now.
            margin = min(clearance_margin(self.scene.move_scene(n, self.scene.starts)) for n in self.scene.names)
            self.paths = TransferPaths(self.scene, margin, self.options.transit)
        else:
            self.model = CollisionModel(self.scene, self.scene.edges)
            self.certificates = Certificates(self.scene, self.model)
            try:
                self.world = SearchWorld.build(self.scene, self.options, self.clock + self.options.time_limit / 2,
                                               progress, cache, self.model)
            except NoStablePush as err:
                self._no_push = err
            except RegionTimeout as timeout:
                self._timeout = str(timeout)
        #: Seconds setting the session up took (the regions, read or computed, and the rest).
        self.setup_s = time.perf_counter() - self.clock

    @property
    def stable_edges(self) -> tuple[int, ...]:
        """The allowed edges that have a stable push, whose regions the session holds."""
        return tuple(c.edge for c in self.world.controls) if self.world is not None else ()

    @property
    def transits(self) -> TransitPlanner | None:
        """The pusher's checked paths between those edges (None where it cannot switch)."""
        return self.world.transits if self.world is not None else None

    def with_friction(self, mu: float) -> "Planner | None":
        """A session of this scene for pusher friction ``mu`` (as a re-plan after a slip asks),
        with this session's options, cache and progress; None if no edge has a stable push at
        ``mu`` or no region was done in time."""
        lower = Planner(replace(self.scene, pusher=replace(self.scene.pusher, mu=mu)), self.options, cache=self._cache,
                        progress=self._progress)
        return lower if lower.world is not None else None

    @property
    def note(self) -> str:
        """What the user should know of this session's regions (edges left out at the time limit)."""
        return self.world.note if self.world is not None else self._timeout

    def _request(self, seed: object, time_limit: object, optimize: object = None, planner: object = None) -> PlanRequest:
        return PlanRequest.of(self.options, seed=seed, time_limit=time_limit, optimize=optimize, planner=planner)

    def _pose(self, value: ArrayLike | None, name: str, default: np.ndarray) -> np.ndarray:
        return default.copy() if value is None else pose(value, name)

    def plan(self, start: ArrayLike | None = None, goal: ArrayLike | None = None, *, seed: int | None = None,
             time_limit: float | None = None, optimize: int | None = None, planner: str | None = None,
             reuse: bool = True, edges: Sequence[int] | None = None, observed: bool = False,
             since: float | None = None) -> Plan:
        """A plan of guaranteed-stable pushes from ``start`` to ``goal`` (``(x, y, theta)``,
        radians; default: the scene's).

        ``seed``, ``time_limit`` (the search's, in seconds), ``optimize`` (improvement rounds) and
        ``planner`` (``'rrt'``, ``'kpiece'`` or ``'est'``) default to the session's options. With
        ``reuse``, a plan this session found before for the same goal is tried first: the start
        joined to it by one or two pushes (module docstring). A plan is always solved or says why
        not (``Plan.reason``); a start where the pusher has no room is bad input. ``edges``, if
        given, are the only edges the first push may be on (a robot re-planning with its pusher on
        the part keeps it there; the plan may still switch, by a checked transit). ``observed``:
        the part is observed at ``start``, so the pusher needs there only the clearance every push
        keeps, not the search's (:class:`~planner.search.context.PlanningContext`). ``since`` (a
        ``time.perf_counter()`` reading; default: now) is when the plan's time and time limit
        start: a session's :attr:`clock` counts its set-up in, as :func:`plan` does.

        A scene of several parts is planned as a whole, every part from its start to its goal:
        ``start``, ``goal`` and ``edges`` are for a scene of one part.

        Raises
        ------
        SceneError
            Naming the argument at fault; :class:`~planner.actions.controls.NoStablePush` if no
            allowed edge has a stable push.
        """
        request = self._request(seed, time_limit, optimize, planner)
        if self.paths is not None:
            found = self._plan_parts(start, goal, request, edges)
        else:
            start = self._pose(start, "start", self.scene.start)
            goal = self._pose(goal, "goal", self.scene.goal)
            if edges is not None and (not isinstance(edges, Sequence)
                                      or not all(isinstance(e, int) and e in self.scene.edges for e in edges)):
                raise SceneError("edges", f"must be allowed edges of the pusher {list(self.scene.edges)}, got {edges}")
            found = self._plan(start, goal, request, time.perf_counter() if since is None else since, reuse, edges,
                               observed)
        if not found.solved and found.reason and not self.options.margin.exact:
            # The margin shrinks every region: a user at the limit of what is reachable should know.
            found = replace(found, reason=f"{found.reason} (with the stability margin: {self.options.margin}; "
                                          "margin 0 plans at the regions' exact limit)")
        return replace(found, margin=self.options.margin)

    def _plan(self, start: np.ndarray, goal: np.ndarray, request: PlanRequest, clock: float,
              reuse: bool = False, edges: Sequence[int] | None = None, observed: bool = False) -> Plan:
        if self._no_push is not None:
            raise self._no_push
        if self.world is None:
            return plan_result(self.scene, request, self.options.switch_cost, clock, start, goal, [], self._timeout)
        context = PlanningContext(self.world, request, start, clock, observed)
        if edges is not None:
            context.starts = [k for k in context.starts if self.world.controls[k].edge in edges]
            context.search_starts = [k for k in context.search_starts if k in context.starts]
            if not context.starts:
                return plan_result(self.scene, request, self.options.switch_cost, clock, start, goal, [],
                                   f"no stable push with room for the pusher at the start on edges {list(edges)}")
        key = tuple(goal.tolist())
        joined = join(self.world, context, goal, self._plans.items(key)) if reuse else None
        found = joined or solve(context, goal)
        if found.solved and found.segments:
            self._plans.file(key, next(self._filings), found)
        return found

    def reachability(self, goals: ArrayLike | None = None, *, start: ArrayLike | None = None,
                     pushes: int | None = None, time_limit: float | None = None,
                     seed: int | None = None, reuse: bool = True) -> list[Reach]:
        """One :class:`~planner.queries.reachability.Reach` per goal (rows ``(x, y, theta)``,
        radians; default: the scene's goal) from ``start`` (default: the scene's), for a scene of
        one part; at most :data:`MAX_GOALS` goals a query.

        Each goal gets the certificates of unreachability
        (:mod:`planner.queries.reachability`); the goals left share one search tree grown towards
        all of them, seeded by ``seed``. ``time_limit`` bounds the whole query, the certificates
        taking at most half of it (default: the certificates' time plus :data:`REACH_BASE_S` plus
        :data:`REACH_PER_GOAL_S` per open goal, at most the options' time limit): a goal not
        certified, nor reached, within it is answered ``'unknown'``, saying so. Every
        ``'reachable'`` answer carries a plan (as found, not shortened), every ``'unreachable'`` a
        certificate; ``pushes`` is a budget of pushes beyond which a plan is answered
        ``'unknown'``. A pose asked several times is answered once: the copies share its answer.
        With ``reuse``, what earlier queries from the same start reached serves this one: a goal
        reached before is answered by its plan, and goals are also reached from where plans to
        goals near them end (the session keeps :data:`REMEMBERED_GOALS` of them); the answers then
        depend on the queries before, as a map drawn goal by goal grows.

        Raises
        ------
        SceneError
            Naming the argument at fault (``goals`` beyond :data:`MAX_GOALS`), or ``scene`` for a
            scene of several parts.
        """
        clock = time.perf_counter()
        self.scene.one_part("reachability")
        start = self._pose(start, "start", self.scene.start)
        rows = self.scene.goal[None] if goals is None else poses(goals, "goals")
        if len(rows) > MAX_GOALS:
            raise SceneError("goals", f"{len(rows)} goals, more than {MAX_GOALS} a query: ask in batches")
        if pushes is not None and integer(pushes, "pushes") < 0:
            raise SceneError("pushes", f"must be >= 0, got {pushes}")
        limit = self._request(seed, time_limit).time_limit  # checked before any work; None: the options'
        # Each pose once: the search tests a new state against the goals nearest it, so copies of a
        # pose would crowd each other out there, and the same pose get different answers.
        _, first, copies = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")  # the poses in the order they were first asked
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        unique = rows[first[order]]
        reasons: list[str | None] = []
        for goal in unique:
            if time.perf_counter() >= clock + limit / 2:  # the rest of the time is the search's
                break
            reasons.append(self._reason(goal, start))
        certified = time.perf_counter()
        self.timings = {"certificates": certified - clock, "connections": 0.0, "growth": 0.0}
        if time_limit is None:
            limit = min(limit, certified - clock + REACH_BASE_S + REACH_PER_GOAL_S * reasons.count(None))
        scene = self.scene if np.array_equal(start, self.scene.start) else self.scene.with_part(start=start)
        if certified >= clock + limit:  # no time left to search: the goals open are not looked for
            late = f"the time limit of {limit:g} s ran out before the search"
            found = [Reach("unreachable", None, r, None, scene, g, self.options) if r
                     else Reach("unknown", None, late, None, scene, g, self.options) for g, r in zip(unique, reasons)]
        elif self.world is None and self._no_push is None:  # no region in time: nothing certain but the geometry
            found = [Reach("unreachable", None, r, None, scene, g, self.options) if r
                     else Reach("unknown", None, self._timeout, None, scene, g, self.options)
                     for g, r in zip(unique, reasons)]
        else:
            context = (None if self.world is None
                       else PlanningContext(self.world, self._request(seed, limit), start, clock))
            key = tuple(start.tolist())
            found = answers(scene, self.options, context, reasons, unique[:len(reasons)], pushes, self.timings,
                            self._reached.filed(key) if reuse else None)
            if reuse:
                for answer in found:
                    if answer.plan is not None and answer.plan.solved and answer.plan.segments:
                        self._reached.file(key, tuple(answer.goal.tolist()), answer.plan.segments)
        unchecked = f"not looked at: the certificates of the goals before it took their half of the time limit of {limit:g} s"
        found += [Reach("unknown", None, unchecked, None, scene, g, self.options) for g in unique[len(reasons):]]
        return [found[k] for k in rank[copies.ravel()].tolist()]

    def _plan_parts(self, start: object, goal: object, request: PlanRequest, edges: object) -> Plan:
        """:meth:`plan` of a scene of several parts: every part from its start to its goal, or as
        far as the search got (``solved`` False, ``delivered`` naming the parts at their goals)."""
        for name, value in (("start", start), ("goal", goal), ("edges", edges)):
            if value is not None:
                raise SceneError(name, "is for a scene of one part: a scene of several plans from each part's start "
                                       "to its goal")
        return plan_parts(self.scene, self.options, self.move_session, self.paths, request.seed, request.time_limit)

    def move_session(self, part: str, poses: Mapping[str, np.ndarray] | None) -> "Planner":
        """The one-part session of moving ``part`` of a scene of several with the others at
        ``poses``, or (``poses`` None) among the obstacles alone; kept: the
        :data:`REMEMBERED_PLANS` latest."""
        key = (part, *(() if poses is None else (tuple(np.round(poses[n], 9).tolist())
                                                 for n in self.scene.names if n != part)), poses is None)
        session = self._moves.get(key, part)
        if session is None:
            alone = self.scene.move_scene(part, self.scene.starts if poses is None else poses, others=poses is not None)
            session = Planner(alone, self.options, cache=self._cache, progress=self._progress)
        self._moves.file(key, part, session)  # the latest used, the last dropped
        return session

    def clear(self) -> None:
        """Forget what the queries found (plans per goal, goals reached, move sessions), as OMPL's
        ``SimpleSetup.clear`` does, keeping the set-up (regions, collisions, transits): the next
        query answers as a fresh session's would, faster.

        >>> from planner import load_scene
        >>> scene = load_scene("scenes/parking.yaml")
        >>> session, moved = Planner(scene), scene.start + [0.005, 0.0, 0.02]
        >>> _ = session.plan(seed=1)
        >>> session.plan(start=moved, seed=1).headline()          # joined to the first plan
        '6 pushes, cost 0.823 m, length 0.823 m'
        >>> session.clear()
        >>> session.plan(start=moved, seed=1).headline() == Planner(scene).plan(start=moved, seed=1).headline()
        True
        """
        self._plans, self._reached, self._moves = (Memory(m.limit) for m in (self._plans, self._reached, self._moves))

    def certify_unreachable(self, goal: ArrayLike | None = None, *, start: ArrayLike | None = None) -> str | None:
        """Why ``goal`` (default: the scene's) is certainly unreachable from ``start`` (default:
        the scene's), or None if no certificate shows it (:mod:`planner.queries.reachability`);
        for a scene of one part."""
        self.scene.one_part("certify_unreachable")
        return self._reason(self._pose(goal, "goal", self.scene.goal), self._pose(start, "start", self.scene.start))

    def _reason(self, goal: np.ndarray, start: np.ndarray) -> str | None:
        """:meth:`certify_unreachable` of poses checked already."""
        reason = self.certificates(goal, start)
        if reason is None and self._no_push is not None and not self.scene.within_tolerance(start, goal):
            reason = f"no stable push: {self._no_push.problem}"
        return reason

    def reachable_set(self, pushes: int = 1, heading: float | None = None, resolution: float | None = None,
                      **kwargs: Any) -> ReachableSet:
        """The map of goal positions reachable from the scene's start in at most ``pushes`` (1 or
        2) stable pushes (:func:`planner.queries.reachable_set.reachable_set`), on this session's
        regions and collision model."""
        self.scene.one_part("reachable_set")
        return reachable_set(self.scene, pushes, heading, resolution,
                             controls=None if self.world is None else self.world.controls, regions=self.options.regions,
                             margin=self.options.margin,
                             **kwargs)


def session_options(scene: Scene, options: PlannerOptions | Mapping[str, Any] | None) -> PlannerOptions:
    """A session's options, resolved once: a :class:`PlannerOptions` in place of the scene's own
    (checked as any options are: one may be made without its checks), or a mapping of changes to
    the scene's own (:attr:`~planner.model.scene.Scene.options`: its file's ``planner:`` block and
    ``pusher.transit``).

    >>> from planner import load_scene
    >>> session_options(load_scene("scenes/narrow_junction.yaml"), {"seed": 7})
    PlannerOptions(name='rrt', time_limit=10.0, seed=7, regions='exact', switch_cost=0.25, optimize=0, transit='lift', margin=Margin(mu=0.1, cf=0.02))
    """
    if isinstance(options, PlannerOptions):
        return PlannerOptions().merged(asdict(options))
    if options is None or isinstance(options, Mapping):
        return scene.options.merged(options)
    raise SceneError("options", f"must be PlannerOptions or a mapping, got {type(options).__name__}")


def plan(scene: Scene, *, seed: int | None = None, time_limit: float | None = None,
         planner: str | None = None, regions: str | None = None, transit: str | None = None,
         switch_cost: float | None = None, optimize: int | None = None, margin: Any = None,
         progress: Callable[[int, int], None] | None = None) -> Plan:
    """Plan guaranteed-stable pushes from ``scene.start`` to ``scene.goal``: a fresh
    :class:`Planner` session asked once.

    Arguments left as None take the scene's own options (its file's ``planner:`` block and
    ``pusher.transit``):
    ``regions`` is ``'stable'`` (procedure STABLE) or ``'exact'`` (the default); ``transit``
    ``'plane'``, ``'lift'`` or ``'none'``; ``switch_cost`` in metres; ``optimize`` a number of
    improvement rounds; ``margin`` the stability margin (a :class:`~planner.model.margin.Margin`,
    ``{"mu": ..., "cf": ...}``, ``[mu, cf]`` or 0 for the exact limit). With a given seed, a run that solves within the time limit returns the
    same plan every time; a scene of several parts is planned as a whole (:meth:`Planner.plan`).
    The time limit bounds the stable regions (which may take half of it; edges not done are left
    out, as ``Plan.note`` says) and the search together.

    Raises
    ------
    SceneError
        Naming the argument at fault, or if no allowed edge can start pushing.
    """
    options = {k: v for k, v in (("time_limit", time_limit), ("seed", seed), ("regions", regions),
                                 ("switch_cost", switch_cost), ("optimize", optimize), ("transit", transit),
                                 ("margin", margin))
               if v is not None}
    if planner is not None:
        options["name"] = check_planner(planner, "planner")
    session = Planner(scene, options, progress=progress)
    return session.plan(since=session.clock)


def reachability(scene: Scene, goals: ArrayLike | None = None, *, pushes: int | None = None,
                 time_limit: float | None = None, seed: int | None = None) -> list[Reach]:
    """:meth:`Planner.reachability` of a fresh session: one answer per goal (rows ``(x, y,
    theta)``, radians; default: the scene's goal) from the scene's start.

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/battery.yaml")
    >>> [(r.status, r.pushes) for r in reachability(scene, [scene.goal, [9.0, 9.0, 0.0]])]
    [('reachable', 1), ('unreachable', None)]
    """
    return Planner(scene).reachability(goals, pushes=pushes, time_limit=time_limit, seed=seed)
