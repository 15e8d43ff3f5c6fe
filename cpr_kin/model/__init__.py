"""The robot as loaded.

The robot as loaded: :class:`~cpr_kin.model.robot.Robot` (models, limits, collision groups),
its frames, joint limits, packages of mesh files, default joints and tool (``arm``), the
collision geometries' groups and how far each hull reaches beyond its mesh (``hull_excess``).
"""
