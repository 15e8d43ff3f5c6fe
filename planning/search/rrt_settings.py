"""Settings of RRT-Connect (:mod:`planning.search.rrt_connect`), validated on construction.

Why each default is what it is, with the measurements behind it: ``docs/tuning.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

from planning.validation import integer_in, number_in

RANGE_FRACTION = 0.2
"""Default extension step as a fraction of the sampling box's diagonal (OMPL's default range)."""
LOCAL_SHARE = 0.2
"""Default share of the samples drawn near a node of the tree they extend (see its setting)."""
LOCAL_SPREAD = 0.05
"""Default standard deviation of those samples about their node [share of each joint's range]."""
JOINT_SHORTCUTS = 0
"""Default attempts to straighten one joint of a found path (see its setting): none (``docs/tuning.md``)."""


@dataclass(frozen=True)
class RrtSettings:
    """Parameters of :func:`~planning.search.rrt_connect.rrt_connect`; validated on construction.

    Attributes:
        max_samples: random samples before giving up, in [1, 100000].
        step_m: longest extension towards a sample, as a robot motion bound [m], in (0, 10];
            ``None``: :data:`RANGE_FRACTION` of the sampling box's diagonal (in the same
            motion bound), at least ``resolution_m``.
        resolution_m: spacing of the checked configurations along the returned path's
            edges [m], in (0, step_m] (or (0, 10] with the default step).
        explore_resolution_m: their spacing while the trees grow and the path is shortened
            [m], at least ``resolution_m`` (``None``: the same); the path found is then
            checked at ``resolution_m`` and its blocked edges planned again at that spacing
            (:mod:`planning.search.rrt_connect`).
        shortcuts: random shortcut attempts on the found path, in [0, 10000].
        joint_shortcuts: attempts to straighten one joint of the shortened path where that
            makes it faster at the joints' speeds, in [0, 10000] (given the speeds:
            :func:`planning.search.edges.straighten_joints`).
        local_share: share of the samples drawn near a node of the tree they extend, in
            [0, 1] (:mod:`planning.search.rrt_connect`); 0: every sample uniform in the box, as RRT-Connect's.
        local_spread: standard deviation of those samples about their node [share of each
            joint's range], in (0, 1].
    """

    max_samples: int = 3000
    step_m: float | None = None
    resolution_m: float = 0.02
    explore_resolution_m: float | None = None
    shortcuts: int = 20
    joint_shortcuts: int = JOINT_SHORTCUTS
    local_share: float = LOCAL_SHARE
    local_spread: float = LOCAL_SPREAD

    def __post_init__(self) -> None:
        integer_in("max_samples", self.max_samples, 1, 100_000)
        if self.step_m is not None:
            number_in("step_m", self.step_m, 0.0, 10.0, low_open=True, unit="m")
        high = 10.0 if self.step_m is None else self.step_m
        number_in("resolution_m", self.resolution_m, 0.0, high, low_open=True, unit="m")
        if self.explore_resolution_m is not None:
            number_in("explore_resolution_m", self.explore_resolution_m, self.resolution_m, high, unit="m")
        integer_in("shortcuts", self.shortcuts, 0, 10_000)
        integer_in("joint_shortcuts", self.joint_shortcuts, 0, 10_000)
        number_in("local_share", self.local_share, 0.0, 1.0)
        number_in("local_spread", self.local_spread, 0.0, 1.0, low_open=True)
