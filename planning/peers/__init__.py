"""Peer planners for the benchmarks: OMPL's and pyroboplan's RRT-Connect with TOPP-RA timing.

Optional (``pip install '.[bench]'``); the core never imports this package.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
