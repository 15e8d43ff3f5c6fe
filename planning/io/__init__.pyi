"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .bundled import bundled_scene_paths, paper_scene, paper_scene_path
from .outputs import plan_files
from .publish import FolderLock, OutputError, OutputFolder, write_file
from .report import plan_record, report_markdown, summary
from .scene_file import (
    SceneFile,
    dump_scene,
    load_scene,
    load_scene_file,
    parse_scene,
    parse_scene_file,
    scene_document,
)
from .task_outputs import task_document, task_files
from .trajectory_io import write_samples, write_trajectory
from .trajectory_reader import TrajectoryFile, TrajectoryFileError, parse_trajectory, read_trajectory

__all__ = [
    "FolderLock",
    "OutputError",
    "OutputFolder",
    "SceneFile",
    "TrajectoryFile",
    "TrajectoryFileError",
    "bundled_scene_paths",
    "dump_scene",
    "load_scene",
    "load_scene_file",
    "paper_scene",
    "paper_scene_path",
    "parse_scene",
    "parse_scene_file",
    "parse_trajectory",
    "plan_files",
    "plan_record",
    "read_trajectory",
    "report_markdown",
    "scene_document",
    "summary",
    "task_document",
    "task_files",
    "write_file",
    "write_samples",
    "write_trajectory",
]
