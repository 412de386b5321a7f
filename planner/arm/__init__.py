"""The arm that holds the pusher: published kinematics and limits of the arms a scene's ``robot:``
block may name (:mod:`.arms`), inverse kinematics for pusher poses on the table (:mod:`.reach`,
mink on MuJoCo) and the joint trajectory along a pusher's trajectory, with whether the arm can
run it (:mod:`.joints`). Needs the ``arm`` extra (mink).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world` and this package.
"""
