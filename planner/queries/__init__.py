"""Questions about a scene answered with the search and the actions: one-step planning
(:mod:`.one_step`), certified reachability (:mod:`.reachability`), reachable-set maps
(:mod:`.reachable_set`), controllability (:mod:`.controllability`) and the geodesic lower bound
on a plan's length (:mod:`.geodesic`).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.actions`, :mod:`planner.search` and this package.
"""
