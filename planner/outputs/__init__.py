"""What a person looks at: the rerun recording (:mod:`.recording`) of the plan's frames
(:mod:`.frames`) and of the pushed edge's mechanics (:mod:`.analysis`), written beside the search
by a forked process (:mod:`.recorder`), and still pictures (:mod:`.picture`, matplotlib), both of
plans of any number of parts, told apart alike (:mod:`.looks`).

Allowed imports: every package below it (:mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.actions`, :mod:`planner.search`, :mod:`planner.queries`,
:mod:`planner.execution`) and this one.
"""
