"""What every part of the toolkit shares, robot or not.

What every part of the toolkit shares, robot or not: the exception base class and its kin
(``errors``), how values are shown in messages (``names``), numba's ``njit`` typed (``compiled``),
bounded reading of what a user wrote (``user_files``), the on-disk cache (``disk_cache``) and
array helpers cheaper to start than NumPy's (``arrays``).

Imports nothing else of :mod:`cpr_kin`, so :mod:`planning` uses it without loading a robot.
"""
