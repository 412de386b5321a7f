"""Seeing the parts: their poses on the table estimated from an overhead depth image.

The camera is the scene's (:class:`planner.model.camera.Camera`, its calibration); a depth image is
what it reports (in a simulation, :mod:`planner.execution.depth_camera`). The image is turned into
heights over the table plane, the plane itself fitted to the image (:mod:`.table_view`), each
known part's outline is found where the heights rise to its top (:mod:`.silhouette`) and
registered to it (:mod:`.registration`); :mod:`.estimation` gives each part's pose with its
covariance and how much of its outline was seen, or says the track is lost
(``docs/camera.md``).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.arm` and this package.
"""
