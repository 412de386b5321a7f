"""The search over pushes and edge switches with OMPL's control planners (Lynch & Mason 1996,
§4): the request and the context a run builds once (:mod:`.context`), the goal region
(:mod:`.goal_region`) and its OMPL adapter (:mod:`.goal`), the OMPL spaces (:mod:`.spaces`), the
path decoder (:mod:`.decode`) and the planning runs, :func:`plan` and :func:`plan_batch`
(:mod:`.planning`).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.actions` and this package.
"""

from .planning import plan, plan_batch

__all__ = ["plan", "plan_batch"]
