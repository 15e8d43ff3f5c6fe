"""Box-constrained batch optimisers behind one interface, and the sampling planner that seeds them.

The firefly algorithm (Yang 2010), the CMA-ES that refines its best (:mod:`.refinement`) and
the baselines they are compared with (:mod:`.baselines`);
RRT-Connect (:func:`.rrt_connect.rrt_connect`), whose paths seed the firefly.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
