"""Forward and inverse kinematics, dynamics and the payload.

Forward kinematics (``forward``), the verified numerical IK (``numerical_ik``), dynamics and
payloads (``dynamics``) and the payload's shape carried as one of the robot's geometries
(``carried``).
"""
