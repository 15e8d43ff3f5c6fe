"""The planner as a pipeline: scene -> problem -> search -> choose -> time -> verify -> result.

Read it in this order; each stage hands the next a frozen value:

=====================  ================================================  ==========================
stage                  module                                            hands over
=====================  ================================================  ==========================
scene                  :mod:`~planning.pipeline.scene`,                  :class:`Scene`
                       :mod:`~planning.pipeline.settings`,
                       :mod:`~planning.pipeline.tuning`
problem                :mod:`~planning.pipeline.problem`                 :class:`Problem` (robot,
                       (:mod:`~planning.pipeline.motion`,                world, motion, duration
                       :mod:`~planning.pipeline.objective`,              rule, objective)
                       :mod:`~planning.pipeline.fitness`,
                       :mod:`~planning.pipeline.path_terms`)
attempt                :mod:`~planning.pipeline.seeding`                 :class:`Attempt` (problem,
                                                                         seeds)
search                 :mod:`~planning.pipeline.search`                  ``SearchResult``
choose, time, verify   :mod:`~planning.pipeline.choose`,                 :class:`Choice` (or a
                       :mod:`~planning.pipeline.timing`,                 ``Refusal``: next attempt)
                       :mod:`~planning.pipeline.verification`
result                 :mod:`~planning.pipeline.result`,                 :class:`PlanResult`
                       :mod:`~planning.pipeline.metrics`
=====================  ================================================  ==========================

:func:`~planning.pipeline.planner.solve` strings them together; :func:`plan` is
``solve(build_problem(scene))``. The rules that vary by setting are objects chosen once:
the duration (:class:`~planning.pipeline.timing.FixedDuration` or ``FreeDuration``), the
fitness (:data:`~planning.pipeline.fitness.FITNESS_RULES`), the executed path
(:func:`~planning.pipeline.path_terms.executed_paths`) and the seeding
(:data:`~planning.pipeline.seeding.SEEDINGS`).
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
