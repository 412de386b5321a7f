"""The table the part moves on: collision checking of the pushed body and of the pusher alone
(:mod:`.validity`, python-fcl), the free space of a disk inside the part with its connected
pieces (:mod:`.free_space`, shapely), the room near a goal (:mod:`.room`) and the spacing of the
grids the planner lays over the table (:mod:`.grid`).

Allowed imports: :mod:`mechanics`, :mod:`planner.model` and this package.
"""
