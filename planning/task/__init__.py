"""Tasks: one trajectory through moves, straight tool lines, waits, attaches and releases.

A task is a sequence of :class:`Segment` (:class:`Move`, optionally under an
:class:`OrientationConstraint`; :class:`ToolLine`; :class:`Wait`; :class:`Attach`;
:class:`Detach`) planned by :func:`plan_task` from a scene's start into one :class:`TaskMotion`:
jerk- and torque-limited, every segment verified with what the robot carries then, among the
obstacles then. A line alone: build a :class:`ToolLine` (to a pose, or by an offset in the
tool's or the base's frame), then :func:`plan_line` it from a configuration: a
:class:`LineMotion` holds the joint path, the timed trajectory, its certified deviation and
its verification. A line that cannot be followed to its end raises
:class:`~planning.errors.ToolLineBrokenError` with the share achieved.
"""

import lazy_loader

# the exports of __init__.pyi, each imported on first use
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
