"""Seeing a plan: the meshcat viewer and matplotlib plots.

Imported only when a display or a plot is asked for: the core never imports this package.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
