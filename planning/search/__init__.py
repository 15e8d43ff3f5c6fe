"""Box-constrained batch optimisers behind one interface.

The firefly algorithm (Yang 2010) and the baselines it is compared with (:mod:`.baselines`).
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
