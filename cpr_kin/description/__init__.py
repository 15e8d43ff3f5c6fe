"""A robot from its description files (URDF, SRDF, limits).

A robot from its description files: :class:`~cpr_kin.description.loading.RobotSpec` and
``load_robot`` (``loading``), its options checked (``robot_options``), the URDF read strictly
(``urdf_file``, ``supported``) into Pinocchio's models (``urdf_models``), the SRDF's groups
(``srdf_groups``) and the bundled files (``resources``); a robot loaded once per thread and
reused while its files are unchanged (``shared_robots``).
"""
