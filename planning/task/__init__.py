"""Task-space motion: the tool frame along straight lines, within a stated deviation at every instant.

Build a :class:`ToolLine` (to a pose, or by an offset in the tool's or the base's frame), then
:func:`plan_line` it from a configuration: a :class:`LineMotion` holds the joint path, the
timed trajectory (jerk- and torque-limited, at rest at both ends), its certified deviation
and the verification every trajectory of the planner passes. A line that cannot be followed
to its end raises :class:`~planning.errors.ToolLineBrokenError` with the share achieved.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
