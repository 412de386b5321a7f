"""What the pusher can do, each action checked against the world: the stable pushes of each edge
(:mod:`.controls`, over the region cache of :mod:`.region_cache`), one checked push between two
poses (:mod:`.push`), each edge's car (:mod:`.car`) and its Dubins curves (:mod:`.dubins`), and the
pusher's transits between edges (:mod:`.transit`).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world` and this package.
Nothing here knows of OMPL's planners or of a search.
"""
