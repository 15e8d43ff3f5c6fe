"""The bounds of a task's values, one place for the task's classes and the scene file's schema.

A scene file's ``task:`` is checked against these before a segment is built
(:mod:`planning.io.task_entry`), so that reading a scene file needs them without the classes.
"""

from __future__ import annotations

import math

SHORTEST_LINE_M = 1e-4
"""Shortest translation of a line [m]; a pure rotation must turn at least :data:`SHORTEST_TURN_RAD`."""
SHORTEST_TURN_RAD = 1e-3
"""Smallest rotation of a line without translation [rad]."""
FINEST_POSITION_M = 1e-6
"""The finest position tolerance of a line [m]: its samples are put on the line to a thousandth
of the tolerance, and the certified check's samples come closer the finer it is."""
FINEST_ANGLE_RAD = 1e-5
"""The finest angle tolerance of a line [rad]."""
COARSEST_POSITION_M = 0.1
"""The coarsest position tolerance of a line [m]."""
COARSEST_ANGLE_RAD = math.pi / 4
"""The coarsest angle tolerance of a line [rad]."""
LINE_POSITION_M = 1e-3
"""The default position tolerance of a line [m]."""
LINE_ANGLE_RAD = 0.01
"""The default angle tolerance of a line [rad]."""
FASTEST_TOOL_M_S = 100.0
"""The largest tool speed limit of a line [m/s]."""
UPRIGHT_RAD = math.radians(5.0)
"""The default angle of an orientation constraint [rad]: 5 degrees."""
LONGEST_WAIT_S = 3600.0
"""The longest wait of a task [s]."""
