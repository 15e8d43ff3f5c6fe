"""MotionBenchMaker problems, from the ``vamp-planner`` 0.6.4 source distribution on PyPI.

Its ``resources/{panda,ur5,fetch}/`` hold the robot (URDF, SRDF, meshes) and
``problems.tar.bz2``: per class (``table_pick``, ``box``, ``cage``, ...) 100 problems, each a
MoveIt ``sceneNNNN.yaml`` (``PlanningScene``) and ``requestNNNN.yaml`` (``MotionPlanRequest``).
:func:`vamp_resources` downloads the archive from the package index once (its SHA-256 checked
against the index's), into a cache folder (``$CPR_FIREFLY_CACHE``, else
``$XDG_CACHE_HOME/cpr-firefly``, else ``~/.cache/cpr-firefly``), and unpacks what is asked.
"""

from __future__ import annotations

import hashlib
import os
import re
import tarfile
import urllib.parse
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import cpr_kin as ck
from cpr_kin.common.disk_cache import cache_folder
from planning.errors import PlanningError
from planning.pipeline.settings import MAX_SEED
from planning.validation import integer_in

if TYPE_CHECKING:
    from planning.pipeline.scene import Scene

VERSION = "0.6.4"
SDIST = f"vamp_planner-{VERSION}.tar.gz"
INDEX_URL = "https://pypi.org/simple/vamp-planner/"
CLASSES = (
    "table_pick",
    "table_under_pick",
    "box",
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "cage",
)
"""MotionBenchMaker's problem classes, in the order its papers list them."""
ROBOTS = ("panda", "ur5", "fetch")


def _download(target: Path) -> None:
    """Fetch the source distribution from the index into ``target``, its SHA-256 checked."""
    index = os.environ.get("PIP_INDEX_URL", "https://pypi.org/simple").rstrip("/") + "/vamp-planner/"
    with urllib.request.urlopen(index, timeout=120) as response:
        page = response.read().decode()
    found = re.search(rf'href="([^"]*{re.escape(SDIST)})#sha256=([0-9a-f]{{64}})"', page)
    if found is None:
        raise PlanningError(f"{SDIST} is not on the package index {index}")
    url, digest = found.groups()
    url = urllib.parse.urljoin(index, url)
    partial = target.with_suffix(f".{os.getpid()}.part")  # processes downloading at once each write their own
    with urllib.request.urlopen(url, timeout=600) as response, partial.open("wb") as out:
        out.write(response.read())
    if hashlib.sha256(partial.read_bytes()).hexdigest() != digest:
        partial.unlink()
        raise PlanningError(f"{url}: the download's SHA-256 is not the index's {digest}")
    partial.replace(target)


def vamp_resources(robot: str) -> Path:
    """The folder of ``robot``'s resources (URDF, SRDF, meshes) and unpacked ``problems/``, cached."""
    if robot not in ROBOTS:
        raise PlanningError(f"robot '{robot}' is not one of MotionBenchMaker's {list(ROBOTS)}")
    cache = cache_folder()
    folder = cache / f"vamp_planner-{VERSION}" / "resources" / robot
    if not (folder / "problems").is_dir():
        cache.mkdir(parents=True, exist_ok=True)
        archive = cache / SDIST
        if not archive.is_file():
            _download(archive)
        prefix = f"vamp_planner-{VERSION}/resources/{robot}/"
        with tarfile.open(archive) as sdist:
            members = [m for m in sdist.getmembers() if m.name.startswith(prefix) and m.isfile()]
            sdist.extractall(cache, members=members, filter="data")
        with tarfile.open(folder / "problems.tar.bz2") as problems:
            problems.extractall(folder, filter="data")
    return folder


@dataclass(frozen=True)
class Problem:
    """One MotionBenchMaker problem.

    Attributes:
        robot: ``panda``, ``ur5`` or ``fetch``.
        problem_class: its class (:data:`CLASSES`).
        index: its number in the class, from 1.
        scene: the ``PlanningScene`` file.
        request: the ``MotionPlanRequest`` file.
    """

    robot: str
    problem_class: str
    index: int
    scene: Path
    request: Path

    @property
    def name(self) -> str:
        """``<class>_<index>``, e.g. ``box_0042``."""
        return f"{self.problem_class}_{self.index:04d}"


def problems(
    robot: str,
    classes: tuple[str, ...] = CLASSES,
    limit: int | None = None,
    sample_seed: int | None = None,
) -> Iterator[Problem]:
    """The problems of ``robot``'s ``classes``: ``limit`` of each (all: ``None``), in index order.

    Args:
        robot: ``panda``, ``ur5`` or ``fetch``.
        classes: the classes, in the order given.
        limit: problems per class, >= 1; ``None``: all of them.
        sample_seed: ``None``: the first ``limit`` of each class; else ``limit`` drawn at
            random from each class, without replacement, by a generator of this seed and the
            class (a sample no one tuned on; the same seed, the same problems of a class
            whichever other classes are asked).
    """
    if limit is not None and limit < 1:
        raise PlanningError(f"limit = {limit} problems per class must be at least 1 (or None: all)")
    if sample_seed is not None:
        integer_in("sample_seed", sample_seed, 0, MAX_SEED)
    folder = vamp_resources(robot) / "problems"
    for problem_class in classes:
        if problem_class not in CLASSES:
            raise PlanningError(f"class '{problem_class}' is not one of {list(CLASSES)}")
        requests = sorted((folder / f"{problem_class}_{robot}").glob("request*.yaml"))
        if sample_seed is not None and limit is not None and limit < len(requests):
            rng = np.random.default_rng([sample_seed, CLASSES.index(problem_class)])
            drawn = np.sort(rng.choice(len(requests), size=limit, replace=False))
            requests = [requests[k] for k in drawn]
        for request in requests[:limit]:
            index = int(request.stem.removeprefix("request"))
            scene = request.with_name(f"scene{index:04d}.yaml")
            yield Problem(robot, problem_class, index, scene, request)


def import_problem(problem: Problem, out: Path) -> Path:
    """Write ``problem`` as the scene file ``out`` as ``cpr-plan import-moveit`` does, margins 0 as in MoveIt.

    The robot is vamp-planner's (its URDF and SRDF beside the problems).

    Raises:
        MoveItImportError: what the conversion cannot represent; SceneError, cpr_kin.UrdfError.
    """
    from planning.io.moveit_import import RobotFiles, import_moveit
    from planning.io.moveit_messages import MotionPlanRequest, PlanningScene, read_message
    from planning.io.moveit_write import write_imported

    folder = vamp_resources(problem.robot)
    files = RobotFiles(urdf=folder / f"{problem.robot}.urdf", srdf=folder / f"{problem.robot}.srdf")
    scene = read_message(problem.scene, PlanningScene)
    request = read_message(problem.request, MotionPlanRequest)
    return write_imported(import_moveit(scene, request, files, problem.name, (0.0, 0.0)), out)


def endpoint_violations(scene: Scene, robot: ck.Robot) -> list[str]:
    """Why the scene's start and goal are not valid in ``robot``'s collision model (empty: both are).

    Each is ``"<start|goal> <what>"``: a joint value out of range, a pose out of reach, or
    what comes inside the safety or self margin, or a configuration the motors cannot hold
    still. Found as the planner finds its ends (:func:`planning.pipeline.endpoints.endpoint`): a
    ``pose`` or ``tcp`` by the IK solution clear of the margins, and held, nearest the start,
    so a pose with such a solution is valid even where the IK's first solution is not.
    """
    from planning.errors import NoSolutionError
    from planning.pipeline.endpoints import endpoint
    from planning.pipeline.problem import scene_robot, scene_world
    from planning.pipeline.torques import scene_dynamics

    try:
        robot = scene_robot(scene, robot)  # as the planner checks it
        dynamics = scene_dynamics(robot, scene)
    except PlanningError as exc:
        return [f"start is refused: {exc}", f"goal is refused: {exc}"]
    world = scene_world(scene, robot)
    found = []
    q_start = None
    for label in ("start", "goal"):
        try:
            q = endpoint(world, scene, label, seed_q=q_start, dynamics=dynamics)
        except (PlanningError, NoSolutionError, ck.CprKinError) as exc:
            found.append(str(exc) if str(exc).startswith(label) else f"{label} is refused: {exc}")
            continue
        if label == "start":
            q_start = q
    return found
