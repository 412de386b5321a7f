"""The planner's options: their choices, defaults and bounds, and the checks that read them.

A scene file's ``planner:`` block and ``pusher.transit`` (read into a :class:`PlannerOptions` by
:mod:`.scene_file`), the ``plan`` command's flags and :func:`planner.plan`'s keywords all take the
same options, so each is checked here once and reported as a
:class:`~planner.model.fields.SceneError` naming the field or flag given (``name``):

>>> check_seed(7, "--seed"), check_regions("exact", "planner.regions")
(7, 'exact')
>>> check_planner("prm", "planner.name")
Traceback (most recent call last):
...
planner.model.fields.SceneError: planner.name: must be one of rrt, kpiece, est, got 'prm'
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from .fields import LENGTH, SceneError, integer, number, shown
from .margin import DEFAULT_MARGIN, Margin, check_margin

__all__ = ["DEFAULT_PLANNER", "DEFAULT_REGIONS", "DEFAULT_SWITCH_COST", "DEFAULT_TRANSIT", "MAX_OPTIMIZE",
           "MAX_SEED", "MAX_TIME_LIMIT", "PLANNERS", "REGIONS", "TRANSITS", "PlannerOptions", "check_optimize",
           "check_planner", "check_regions", "check_seed", "check_switch_cost", "check_time_limit", "check_transit"]

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


@dataclass(frozen=True)
class PlannerOptions:
    """How a scene is planned, apart from what it describes: what a scene file asks for (its
    ``planner:`` block and ``pusher.transit``, :attr:`planner.model.scene.Scene.options`), the
    options of a :class:`planner.Planner` session, the ``plan`` command's flags and a batch task's
    overrides all come down to one of these, made or changed by :meth:`merged` alone. A session
    resolves them once and passes them down as arguments.

    >>> PlannerOptions().merged({"seed": 4, "regions": "stable"}).seed
    4
    >>> PlannerOptions().merged({"time_limit": -1})
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: time_limit: must be > 0, got -1
    >>> PlannerOptions().merged({"speed": 2}, prefix="planner.")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: planner.speed: is not an option (name, time_limit, seed, regions, switch_cost, optimize, transit, margin)
    """

    name: str = DEFAULT_PLANNER
    time_limit: float = 10.0
    seed: int = 1
    regions: str = DEFAULT_REGIONS
    switch_cost: float = DEFAULT_SWITCH_COST
    optimize: int = 0  # improvement rounds after the first plan (planner.search.planning.solve)
    transit: str = DEFAULT_TRANSIT  # how the pusher may change edge (TRANSITS)
    margin: Margin = DEFAULT_MARGIN  # the stability margin every push keeps (planner.model.margin)

    def merged(self, changes: Mapping[str, Any] | None, prefix: str = "") -> "PlannerOptions":
        """These options with ``changes`` (field name to value) applied, each checked; a
        :class:`SceneError` names the field as ``prefix + name``. The one place options are merged."""
        checked = {}
        for key, value in (changes or {}).items():
            if key not in _CHECKS:
                raise SceneError(f"{prefix}{key}", f"is not an option ({', '.join(_CHECKS)})")
            checked[key] = _CHECKS[key](value, f"{prefix}{key}")
        return replace(self, **checked)


def _one_of(value: Any, choices: tuple[str, ...], name: str) -> str:
    """``value`` if it is one of ``choices``; else a :class:`SceneError` naming ``name``."""
    if value not in choices:
        raise SceneError(name, f"must be one of {', '.join(choices)}, got {shown(value)}")
    return value


def check_planner(value: Any, name: str) -> str:
    """``value`` as an OMPL planner's name (:data:`PLANNERS`); else a :class:`SceneError` naming ``name``."""
    return _one_of(value, PLANNERS, name)


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


_CHECKS = {"name": check_planner, "time_limit": check_time_limit, "seed": check_seed, "regions": check_regions,
           "switch_cost": check_switch_cost, "optimize": check_optimize, "transit": check_transit,
           "margin": check_margin}
