"""Whole joint-space curves certified collision-free between their samples.

Whole joint-space curves certified collision-free between their samples: against obstacles
(``motion``, its grid and slack in ``coarse_first``) and against the robot itself (``self_curve``).
"""
