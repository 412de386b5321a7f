"""Benchmarks, run as scripts that print numbers: planners on the shipped scenes with OMPL's
benchmark log (:mod:`.planners`, :mod:`.ompl_log`), path quality against lower bounds
(:mod:`.quality`), batched reachability (:mod:`.reach`), the search's step rate
(:mod:`.step_rate`), plans run in MuJoCo (:mod:`.simulate`), the stability margin's cost and robustness
(:mod:`.margin`), batch runs on each engine
(:mod:`.batch`) and plans beside a thread holding their frames (:mod:`.stale_stress`).

Allowed imports: every package of :mod:`planner` and its public API (:mod:`planner` itself),
but not the command line.
"""
