"""Distances of the robot to obstacles and to itself.

Distances of the robot to obstacles and to itself: the coal world (``world``) and the pairs
it checks (``touch_links``), clearances, the closest pair visited by its bounds
(``closest_pairs``), margin tests of the pairs the bounds leave (``obstacle_tests``), coal's
batched margin tests (``coal_pools``), which samples coal must compute (``decisive``), the
self-collision model (``self_collision``, ``self_split``, ``self_screen``, ``near_cells``,
``world_self_pairs``), the voxels the robot stands in (``self_filter``) and the robot's reach
against obstacles (``robot_reach``).
"""
