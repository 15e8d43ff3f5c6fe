"""A robot loaded once per thread and reused while its files stay as they were read.

Loading a robot reads its URDF, SRDF, limits and meshes and builds its models: for an arm of
meshes, longer than a warm plan of it takes (``docs/benchmarks.md``). A program that plans
scene after scene with ``plan(scene)`` asks for the same robot each time; :func:`shared_robot`
loads it on the first call and hands the same :class:`~cpr_kin.model.robot.Robot` back while
nothing it was built from has changed.

- **Per thread.** A robot's computations share its Pinocchio data
  (:attr:`~cpr_kin.model.robot.Robot.data`): two plans at once in one process (a Dask worker's
  threads, a user's thread pool) must not share a robot, or one may read the other's forward
  kinematics between two calls. Each thread gets its own.
- **Its files as read.** The URDF, SRDF and limits file it was read from, every collision mesh,
  and the folders where a default SRDF or limits file is looked for (a file added there
  changes the folder's time stamp) are compared by size and modification time on every
  call; any change loads the robot again.
- **Bounded.** At most :data:`KEPT_ROBOTS` robots are kept, the least recently used dropped
  first: an arm of meshes holds hundreds of megabytes.

A robot reused gives the same plans to the bit as a fresh one (``tests/test_shared_robots.py``):
what it keeps between plans (the near cells it has learned) changes only how fast a query
is answered. :func:`forget_shared_robots` drops them all (a test, or memory wanted back).
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

from cpr_kin.description.loading import RobotSpec
from cpr_kin.model.robot import Robot

KEPT_ROBOTS = 8
"""Most robots kept across threads and specs (a batch worker of several threads keeps one each);
the least recently used goes first."""

Stamp = tuple[int, int] | None
"""A file's size [bytes] and modification time [ns] (``None``: it does not exist)."""


@dataclass(frozen=True)
class _Kept:
    """A loaded robot, what it was built from and their stamps."""

    robot: Robot
    sources: tuple[str, ...]
    stamps: tuple[Stamp, ...]


_kept: OrderedDict[tuple[RobotSpec, str, int], _Kept] = OrderedDict()
_lock = threading.Lock()


def shared_robot(spec: RobotSpec) -> Robot:
    """``spec``'s robot, loaded on this thread's first call and kept while its files are unchanged.

    Raises what :meth:`RobotSpec.load <cpr_kin.description.loading.RobotSpec.load>` raises; a
    failed load keeps nothing, nor does a load during which the URDF changed.
    """
    urdf = os.path.abspath(spec.urdf)  # a relative URDF is the working folder's
    key = (spec, urdf, threading.get_ident())
    with _lock:
        kept = _kept.get(key)
        if kept is not None:
            _kept.move_to_end(key)
    if kept is not None and _stamps(kept.sources) == kept.stamps:
        return kept.robot
    before = _stamps((urdf,))
    robot = spec.load()
    sources = _sources(robot)
    fresh = _Kept(robot, sources, _stamps(sources))
    if fresh.stamps[0] != before[0]:  # the URDF changed while it was read: the robot may be of neither
        return robot
    with _lock:
        _kept[key] = fresh
        _kept.move_to_end(key)
        while len(_kept) > KEPT_ROBOTS:
            _kept.popitem(last=False)
    return robot


def forget_shared_robots() -> None:
    """Drop every kept robot: the next :func:`shared_robot` call loads again."""
    with _lock:
        _kept.clear()


def _sources(robot: Robot) -> tuple[str, ...]:
    """What ``robot`` was built from, its URDF first: its files, collision meshes and the folders searched."""
    urdf = Path(robot.urdf_path).absolute()
    files = (urdf, robot.srdf_path, robot.limits_path)
    # a mesh's path is absolute once resolved; a primitive's names its shape (``BOX``)
    meshes = (g.meshPath for g in robot.collision_model.geometryObjects if os.path.isabs(g.meshPath))
    folders = (urdf.parent, urdf.parent.parent / "srdf")  # a default SRDF or limits file appears there
    found = (os.fspath(path) for path in (*files, *meshes, *folders) if path is not None)
    return tuple(dict.fromkeys(found))


def _stamps(paths: tuple[str, ...]) -> tuple[Stamp, ...]:
    """Each path's size and modification time, ``None`` where it is missing."""
    stamps: list[Stamp] = []
    for path in paths:
        try:
            status = os.stat(path)
        except OSError:
            stamps.append(None)
        else:
            stamps.append((status.st_size, status.st_mtime_ns))
    return tuple(stamps)
