"""cpr_kin: any serial robot from its URDF and SRDF as a Pinocchio/coal model.

Loading (:class:`RobotSpec`, :func:`load_robot`), kinematics, verified inverse kinematics of
the tool frame, and signed clearance of the robot's collision groups to obstacles and to
itself, for single configurations, batches and whole joint-space curves, certified between
samples. The CPR of the paper (R-P-P:R-R) is a preset (:mod:`cpr_kin.presets`). Nothing here
draws or plans.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use: a process that needs one module
# (the batch's parent, a tool reading a scene file) does not pay for all the others
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
