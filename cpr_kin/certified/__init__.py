"""Whole joint-space curves certified collision-free between their samples.

Whole joint-space curves certified collision-free between their samples: against obstacles
(``motion``, with ``interval_motion``) and against the robot itself (``self_curve``).
"""
