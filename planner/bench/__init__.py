"""Benchmarks, run as scripts that print numbers: planners on the shipped scenes with OMPL's
benchmark log (:mod:`.planners`, :mod:`.ompl_log`), path quality against lower bounds
(:mod:`.quality`), batched reachability (:mod:`.reach`), the search's step rate
(:mod:`.step_rate`) and plans run in MuJoCo (:mod:`.simulate`).

Allowed imports: every package of :mod:`planner` and its public API (:mod:`planner` itself),
but not the command line.
"""
