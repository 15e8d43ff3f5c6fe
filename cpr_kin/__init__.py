"""cpr_kin: the CPR cylindrical manipulator (R-P-P:R-R) as a Pinocchio/coal model.

Kinematics, analytic inverse kinematics of the tool-centre point, and signed clearance of
the robot's collision groups to static obstacles, for single configurations, batches and
whole joint-space curves. Nothing here draws or plans.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use: a process that needs one module
# (the batch's parent, a tool reading a scene file) does not pay for all the others
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
