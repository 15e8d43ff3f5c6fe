"""The robot files that ship with the toolkit: package data of ``cpr_kin`` (``cpr_kin.urdf``).

This folder is the top-level ``urdf/`` of the repository; ``pyproject.toml`` maps it to the
package ``cpr_kin.urdf`` in the wheel and in an editable install. It holds the CPR's URDF
(``cpr.urdf``), SRDF (``cpr.srdf``) and acceleration and jerk limits (``cpr_limits.yaml``),
and in ``makers/`` the limits files of arm makers' datasheets (``<robot name>_limits.yaml``).
"""
