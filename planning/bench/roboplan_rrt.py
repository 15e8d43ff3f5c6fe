"""roboplan's RRT-Connect, path shortcutting and TOPP-RA (C++ on Pinocchio and coal): the compiled peer.

The peer is given our collision model (:class:`RoboplanPeer`, built once per scene and
untimed): the robot's URDF with every link mesh replaced by its convex hull (the shape our
robot checks, written to a temporary folder); the scene's boxes, spheres, cylinders and
convex meshes; exactly our robot's self pairs (those its SRDF disables, the scene allows,
adjacent links and links touching by design left out); our joint velocity, acceleration and
jerk limits; the held joints at their values. :meth:`RoboplanPeer.plan` times what a roboplan
user runs: RRT-Connect, the shortcutter and TOPP-RA (Hermite: at rest at each waypoint, on
the path). Its path is then checked, untimed, by our certified continuous checks (each
straight segment, the obstacles at the scene's margin and the robot's own pairs at its self
margin): roboplan checks configurations a step apart, without a margin. Needs the ``bench``
extra (``roboplan``).
"""

from __future__ import annotations

import itertools
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from lxml import etree
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.description.supported import checked_urdf
from cpr_kin.description.urdf_file import prepared_xml
from cpr_kin.model.packages import package_roots
from planning.errors import PlanningError
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]
GROUP = "planned"
"""The roboplan joint group of the scene's planned joints."""
MAX_NODES = 100_000
"""RRT nodes roboplan may grow: its time limit, not this, ends a search."""


@dataclass(frozen=True)
class PeerResult:
    """One roboplan run.

    Attributes:
        success: a path was found and timed.
        reason: why not, when it failed.
        planning_time_s: RRT-Connect, shortcutting and TOPP-RA [s].
        waypoints: ``(K, nq)`` the shortcut path's vertices.
        duration_s: TOPP-RA's trajectory duration [s].
        certified: the path passes our certified checks at the scene's steps, as ``cpr-plan
            check`` verifies a trajectory (obstacles and the robot's own pairs).
        certified_fine: it passes them at a tenth of those steps: a path that fails only at
            the scene's steps comes within a step of contact without touching.
        samples: ``(times (K,), positions (K, nq), velocities, accelerations)`` of TOPP-RA's
            trajectory, as roboplan samples it.
    """

    success: bool
    reason: str
    planning_time_s: float
    waypoints: FloatArray
    duration_s: float = float("nan")
    certified: bool = False
    certified_fine: bool = False
    samples: tuple[FloatArray, ...] = ()


class RoboplanPeer:
    """A scene in roboplan, with our collision model (module docstring); plan it with :meth:`plan`.

    Raises:
        PlanningError: an obstacle roboplan has no shape for (a capsule), a robot
            without its URDF's file.
    """

    def __init__(self, scene: Scene, robot: ck.Robot | None = None) -> None:
        from roboplan.core import Scene as PeerScene
        from roboplan.core import loadJointLimitsConfig, loadUrdfSceneDescriptionFromXml

        if scene.robot is None:
            raise PlanningError("the roboplan peer needs the scene's robot files (robot: in the scene)")
        self.problem: Problem = build_problem(scene, robot)
        self._folder = tempfile.TemporaryDirectory(prefix="roboplan-")
        folder = Path(self._folder.name)
        spec, robot = scene.robot, self.problem.robot
        xml = _hull_urdf(spec.urdf, spec.package_dirs, folder)
        self.scene = PeerScene("peer", loadUrdfSceneDescriptionFromXml(xml))
        limits = robot.limits
        config = {
            name: {"max_velocity": [float(v)], "max_acceleration": [float(a)], "max_jerk": [float(j)]}
            for name, v, a, j in zip(
                limits.names, limits.velocity, limits.acceleration, limits.jerk, strict=True
            )
        }
        (folder / "limits.yaml").write_text(yaml.safe_dump({"joint_limits": config}))
        self.scene.importJointLimitsFromConfig(loadJointLimitsConfig(folder / "limits.yaml"))
        self.scene.addGroup(GROUP, list(limits.names))
        links = sorted({g.link for g in robot.geometries})
        checked = {
            frozenset((robot.geometries[a].link, robot.geometries[b].link)) for a, b in robot.self_pairs
        }
        checked -= {frozenset(pair) for pair in scene.allowed_collisions}
        unchecked = [(a, b) for a, b in itertools.combinations(links, 2) if frozenset((a, b)) not in checked]
        if unchecked:  # ours: the SRDF's, the scene's, adjacent links, pairs touching by design
            self.scene.setCollisions(unchecked, False)
        for obstacle in scene.obstacles:
            _add_obstacle(self.scene, obstacle, folder)
        names = [f"obstacle:{o.name}" for o in scene.obstacles]
        if len(names) > 1:  # roboplan checks objects against each other too: not a robot's concern
            self.scene.setCollisions(list(itertools.combinations(names, 2)), False)
        actuated = set(self.scene.getJointNames())  # a mimic joint follows its leader in roboplan
        held = {name: value for name, value in robot.held.items() if name in actuated}
        if held:
            q = np.array(self.scene.getCurrentJointPositions())
            q[self.scene.getJointPositionIndices(list(held))] = list(held.values())
            self.scene.setJointPositions(q)

    def plan(self, time_limit_s: float, seed: int = 0) -> PeerResult:
        """RRT-Connect within ``time_limit_s`` [s], shortcutting, TOPP-RA; then our checks (untimed)."""
        from roboplan.core import JointConfiguration, PathShortcutter, PathShortcuttingOptions
        from roboplan.rrt import RRT, RRTOptions
        from roboplan.toppra import PathParameterizerTOPPRA, SplineFittingMode, TOPPRAOptions

        names = list(self.problem.robot.joint_names)
        motion = self.problem.motion
        started = time.perf_counter()
        options = RRTOptions(
            group_name=GROUP, max_nodes=MAX_NODES, max_planning_time=time_limit_s, rrt_connect=True
        )
        planner = RRT(self.scene, options)
        planner.setRngSeed(seed)
        self.scene.setRngSeed(seed)
        try:
            path = planner.plan(
                JointConfiguration(names, np.asarray(motion.q_start)),
                JointConfiguration(names, np.asarray(motion.q_goal)),
            )
        except RuntimeError as exc:  # e.g. "Start configuration is in collision, cannot plan!"
            return PeerResult(False, str(exc), time.perf_counter() - started, np.empty((0, len(names))))
        if not path.positions:
            return PeerResult(False, "no path", time.perf_counter() - started, np.empty((0, len(names))))
        path = PathShortcutter(self.scene, PathShortcuttingOptions(group_name=GROUP, seed=seed)).shortcut(
            path
        )
        timed = PathParameterizerTOPPRA(self.scene, GROUP).generate(
            path, TOPPRAOptions(mode=SplineFittingMode.Hermite)
        )
        elapsed = time.perf_counter() - started
        waypoints = np.array(path.positions, dtype=float)
        samples = tuple(
            np.array(values, dtype=float)
            for values in (timed.times, timed.positions, timed.velocities, timed.accelerations)
        )
        certified = self.certified(waypoints)
        return PeerResult(
            True,
            "",
            elapsed,
            waypoints,
            float(samples[0][-1]),
            certified=certified,
            certified_fine=certified or self.certified(waypoints, step_share=0.1),
            samples=samples,
        )

    def certified(self, waypoints: FloatArray, step_share: float = 1.0) -> bool:
        """Whether every straight segment between ``waypoints`` passes our certified checks.

        ``step_share``: of the scene's steps (the obstacles' and the robot's own pairs').
        """
        from cpr_kin.certified.self_curve import check_self_curve

        world, scene = self.problem.world, self.problem.scene
        steps_m = (scene.planner.verify_step_m * step_share, scene.planner.self_step_m * step_share)
        for a, b in itertools.pairwise(waypoints):
            if not ck.check_segment(world, a, b, scene.safety_margin, steps_m[0]).accepted:
                return False

            def segment(t: FloatArray, a: FloatArray = a, b: FloatArray = b) -> FloatArray:
                return np.asarray(a + np.asarray(t)[:, None] * (b - a))

            if (
                world.self_collision
                and not check_self_curve(
                    world.self_collision, segment, (0.0, 1.0), np.abs(b - a), scene.self_margin, steps_m[1]
                ).accepted
            ):
                return False
        return True


def _add_obstacle(peer: Any, obstacle: ck.Obstacle, folder: Path) -> None:
    """Add ``obstacle`` to the roboplan scene ``peer``, a convex mesh as its hull (an STL in ``folder``).

    Raises:
        PlanningError: a shape roboplan has none for (a capsule, a triangle surface).
    """
    from roboplan.core import Box, Cylinder, Mesh, OcTree, Sphere

    pose, name = np.asarray(obstacle.placement.homogeneous), f"obstacle:{obstacle.name}"
    radius, length = float(obstacle.radius or 0.0), float(obstacle.length or 0.0)
    white = np.ones(4)
    if obstacle.shape == "box":
        peer.addBoxGeometry(name, "universe", Box(*np.asarray(obstacle.size, dtype=float)), pose, white)
    elif obstacle.shape == "sphere":
        peer.addSphereGeometry(name, "universe", Sphere(radius), pose, white)
    elif obstacle.shape == "cylinder":
        peer.addCylinderGeometry(name, "universe", Cylinder(radius, length), pose, white)
    elif obstacle.shape == "mesh" and obstacle.convex:
        hull = folder / f"obstacle_{len(list(folder.iterdir()))}.stl"
        _convex_hull(Path(str(obstacle.mesh)), hull)
        peer.addMeshGeometry(
            name, "universe", Mesh(str(hull), np.full(3, float(obstacle.scale))), pose, white
        )
    elif obstacle.shape == "voxels":  # an octree: coal's boxes (centre, side, occupancy, threshold)
        side = float(obstacle.resolution or 0.0)
        boxes = [np.array([*centre, side, 1.0, 0.5]) for centre in np.asarray(obstacle.points, dtype=float)]
        peer.addOcTreeGeometry(name, "universe", OcTree(boxes, side), pose, white)
    else:
        raise PlanningError(f"the roboplan peer has no {obstacle.shape} shape ('{obstacle.name}')")


def _convex_hull(source: Path, target: Path) -> None:
    """Write the convex hull of the mesh file ``source`` to the STL file ``target`` (trimesh, qhull)."""
    import trimesh

    loaded: Any = trimesh.load(str(source), force="mesh")
    trimesh.Trimesh(vertices=loaded.vertices, faces=loaded.faces).convex_hull.export(str(target))


def _hull_urdf(urdf: Path, package_dirs: tuple[Path, ...], folder: Path) -> str:
    """The URDF as our loader reads it, each collision mesh its convex hull (an STL in ``folder``)."""
    tree = checked_urdf(Path(urdf), validate=False)
    root = etree.fromstring(prepared_xml(tree, Path(urdf), package_roots(Path(urdf), package_dirs)).encode())
    for k, mesh in enumerate(root.iterfind("link/collision/geometry/mesh")):
        hull = folder / f"link_{k}.stl"
        _convex_hull(Path(mesh.get("filename", "")), hull)
        mesh.set("filename", str(hull))
    return str(etree.tostring(root, encoding="unicode"))
