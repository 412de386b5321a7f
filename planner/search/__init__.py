"""The search over pushes and edge switches with OMPL's control planners (Lynch & Mason 1996,
§4): the request and the context a run builds once (:mod:`.context`), the goal region
(:mod:`.goal_region`) and its OMPL adapter (:mod:`.goal`), the OMPL spaces (:mod:`.spaces`), the
path decoder (:mod:`.decode`) and the planning runs, :func:`solve` and :func:`solve_many`
(:mod:`.planning`). :class:`planner.Planner` (:mod:`planner.queries.session`) is their client.

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.actions` and this package.
"""

from .context import PlanningContext, PlanRequest, SearchWorld
from .planning import solve, solve_many

__all__ = ["PlanRequest", "PlanningContext", "SearchWorld", "solve", "solve_many"]
