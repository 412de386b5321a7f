"""The table the part moves on: collision checking of the pushed body and of the pusher alone
(:mod:`.validity`, python-fcl), and the free space of a disk inside the part with its connected
pieces (:mod:`.free_space`, shapely).

Allowed imports: :mod:`mechanics`, :mod:`planner.model` and this package.
"""
