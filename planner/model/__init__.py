"""The data a run reads and writes: scenes of any number of parts (:mod:`.scene`) and their files
(:mod:`.scene_file`, over the hardened YAML reader of :mod:`.yaml_file`), the planner's options
and their checks (:mod:`.options`), checked fields and their one-line errors (:mod:`.fields`),
the moving bodies in the slider frame (:mod:`.bodies`), plans (:mod:`.plan`, moves of the
segments of :mod:`.segments`) and their JSON formats (:mod:`.plan_file`), output files written whole or not at all
(:mod:`.files`), how a run is stopped from outside (:mod:`.stop`) and the processes it starts
beside itself (:mod:`.processes`).

Allowed imports: :mod:`mechanics` and this package only. Everything else in :mod:`planner`
builds on it.
"""
