"""What the benchmarks run on and beside: generated scenes, MotionBenchMaker's problems, the peers.

- scenes: the CPR's random scenes (:mod:`~planning.bench.scene_generator`) and narrow
  passages (:mod:`~planning.bench.narrow_passages`), any arm's blocked scenes
  (:mod:`~planning.bench.arm_scenes`), MotionBenchMaker's problems imported
  (:mod:`~planning.bench.mbm`) and the scripts' selection of them
  (:mod:`~planning.bench.problem_selection`);
- peers: OMPL's and pyroboplan's RRT-Connect with TOPP-RA timing; roboplan's, compiled, on
  our collision model; Ruckig's time-optimal jerk-limited duration, the lower bound of the
  timing benchmarks (optional: ``pip install '.[bench]'``).

Only the scripts, the tests and the examples import this package; ``cpr-plan`` does not.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
