"""The ``format`` tags of the JSON files a plan writes (docs/formats.md), in one place.

A writer puts its tag in the file; a reader checks it; the scene reader names the file a
user gave where a scene belongs (the files of a command taken in the wrong order).
"""

from __future__ import annotations

from typing import Literal, get_args

TrajectoryFormat = Literal["cpr-trajectory/1"]
"""A trajectory file's tag as a type: the one value the reader's schema accepts
(:mod:`planning.io.trajectory_reader`)."""
TRAJECTORY: str = get_args(TrajectoryFormat)[0]
"""A trajectory file's tag, as written (:mod:`planning.io.trajectory_io`, :mod:`planning.io.task_outputs`)."""
OUTPUTS = "cpr-plan-outputs/1"
"""The manifest of a plan's output folder (:mod:`planning.io.publish`)."""
WRITTEN = {TRAJECTORY: "a trajectory file", OUTPUTS: "an output folder's manifest"}
"""What each tag's file is, in words."""
