"""planning: firefly waypoint search, septic smoothing spline and the planner pipeline.

Build a :class:`Scene` (or take :func:`paper_scene`), call :func:`plan`, and inspect the
immutable :class:`PlanResult`: the verified trajectory, its waypoints, metrics, the
optimiser's history and the verification. Write it with :func:`write_trajectory`.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use: a process that needs one module
# (the batch's parent, a tool reading a scene file) does not pay for all the others
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
