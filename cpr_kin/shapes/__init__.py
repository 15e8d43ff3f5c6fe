"""Obstacles and meshes as coal shapes.

Obstacles and meshes as coal shapes: the scene's obstacles (``obstacles``, their ranges in
``obstacle_ranges``), mesh files (``mesh_geometry``), point clouds and octrees as voxels
(``point_clouds``, ``cloud_obstacles``, ``octree_files``), and the exact meshes of concave links
beside the hulls that bound them (``exact_meshes``, ``exact_pairs``).
"""
