"""Peers for the benchmarks: RRT-Connect pipelines and Ruckig's jerk-limited bound.

OMPL's and pyroboplan's RRT-Connect with TOPP-RA timing; roboplan's, compiled, on our
collision model; Ruckig's time-optimal jerk-limited
duration, the lower bound of the timing benchmarks.

Optional (``pip install '.[bench]'``); the core never imports this package.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
