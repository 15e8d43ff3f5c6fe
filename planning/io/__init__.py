"""Files users exchange.

Scene files (YAML), trajectory files (``cpr-trajectory/1``), CSV samples, reports, MoveIt's
planning scenes and requests read, ROS joint trajectories written. The benchmarks' scene
generators are :mod:`planning.bench`'s.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
