"""Cheap conservative bounds of the robot's geometries, no coal query.

Cheap conservative bounds, no coal query: where a geometry can be (``reach``), capsules about
meshes (``capsule_fit``, ``pair_bounds``), compiled forward kinematics of those bounds
(``batch_kinematics``, ``bound_kernels``, ``segments``), the robot's own pairs bounded and
screened (``self_bounds``, ``joint_boxes``, ``self_blocks``), and the pairs that touch or nearly
touch by design (``overlapping_pairs``, ``close_pairs``).
"""
