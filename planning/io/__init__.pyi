"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .outputs import plan_files
from .scene_file import SceneError, dump_scene, load_scene, paper_scene_path, parse_scene, scene_document
from .scene_generator import generate_scenes, random_scene
from .trajectory_io import TrajectoryFile, read_trajectory, write_files, write_samples, write_trajectory

__all__ = [
    "SceneError",
    "TrajectoryFile",
    "dump_scene",
    "generate_scenes",
    "load_scene",
    "paper_scene_path",
    "parse_scene",
    "plan_files",
    "random_scene",
    "read_trajectory",
    "scene_document",
    "write_files",
    "write_samples",
    "write_trajectory",
]
