"""Files users exchange, and the seeded scene generator.

Scene files (YAML), trajectory files (``cpr-trajectory/1``), CSV samples and reports.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
