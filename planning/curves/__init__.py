"""Pure mathematics of joint trajectories, with no robot in it.

The septic smoothing spline (Simon 2004), piecewise polynomials with exact extrema, certified
derivative bounds, samplers at fixed times and point-to-point timing.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
