"""meshcat display of the robot, its obstacles, the safety margin and a trajectory.

Imported only when a display is asked for: ``import planning`` never loads meshcat. The
viewer talks to a loopback-only meshcat server (:mod:`planning.viz.viewer_server`) that it
starts, and can export everything, animation included, as one self-contained HTML file.

Scene tree: ``/robot`` (the robot, visual and collision geometry, the latter hidden by
default), ``/scene/obstacles/<name>``, ``/scene/margin/<name>`` (translucent shells: the
obstacle grown by the margin; a box's shell is the box grown by the margin on every side,
which contains the exact rounded shell), ``/scene/waypoints/<i>`` (TCP at each node),
``/scene/tcp_path`` (coloured by clearance: red at or below the margin, green from
``margin + 0.1 m``), ``/scene/closest`` (the closest robot-obstacle pair at the instant
of smallest clearance) and ``/scene/carried/<name>`` (what a task attaches and releases,
moving with its frame while carried, :mod:`planning.viz.carried_objects`).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from typing import Any

import numpy as np
import pinocchio as pin

with warnings.catch_warnings():  # meshcat 0.3 imports pyzmq's deprecated ioloop module
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat
    import meshcat.geometry as g
    import meshcat.transformations as tf
    import meshcat.visualizer
    from meshcat.animation import Animation
from numpy.typing import NDArray
from pinocchio.visualize import MeshcatVisualizer

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.viz.carried_objects import CarriedSpan, carried_poses
from planning.viz.measured_clearance import MeasuredClearance
from planning.viz.viewer_server import ServerProcess, start_server

FloatArray = NDArray[np.float64]

ROBOT_NODE = "robot"
OBSTACLE_COLOR = 0xD9534F
MARGIN_OPACITY = 0.22
WAYPOINT_COLOR = 0xF0AD4E
CLOSEST_COLOR = 0xE83E8C
CARRIED_COLOR = 0xE69919
"""The colour of what the robot carries (the robot model's own payload colour, ``PAYLOAD_COLOR``)."""


def _material(color: int, opacity: float = 1.0) -> g.MeshLambertMaterial:
    return g.MeshLambertMaterial(
        color=color, opacity=opacity, transparent=opacity < 1.0, depthWrite=opacity >= 1.0
    )


def _shape_objects(obstacle: ck.Obstacle, grow: float) -> list[tuple[Any, FloatArray]]:
    """Meshcat geometries with their poses (in the obstacle frame) of the obstacle grown by ``grow``."""
    to_y = tf.rotation_matrix(np.pi / 2, [1, 0, 0])  # meshcat cylinders run along y, ours along z
    if obstacle.shape == "box":
        return [(g.Box((np.asarray(obstacle.size) + 2 * grow).tolist()), np.eye(4))]
    radius = (obstacle.radius or 0.0) + grow
    if obstacle.shape == "sphere":
        return [(g.Sphere(radius), np.eye(4))]
    length = obstacle.length or 0.0
    if obstacle.shape == "cylinder":
        return [(g.Cylinder(length + 2 * grow, radius), to_y)]
    if obstacle.shape == "capsule":
        ends = [tf.translation_matrix([0, 0, s * length / 2]) for s in (-1, 1)]
        return [(g.Cylinder(length, radius), to_y), *[(g.Sphere(radius), end) for end in ends]]
    if obstacle.shape == "voxels":
        vertices, faces = _cubes(np.asarray(obstacle.points), float(obstacle.resolution or 0.0) / 2 + grow)
        return [(g.TriangularMeshGeometry(vertices, faces), np.eye(4))]
    import trimesh

    mesh: Any = trimesh.load(str(obstacle.mesh), force="mesh")
    if obstacle.convex:
        mesh = mesh.convex_hull
    vertices = np.asarray(mesh.vertices) * obstacle.scale + grow * np.asarray(mesh.vertex_normals)
    return [(g.TriangularMeshGeometry(vertices, np.asarray(mesh.faces)), np.eye(4))]


def _cubes(centres: FloatArray, half_m: float) -> tuple[FloatArray, NDArray[np.int64]]:
    """One triangle mesh of the cubes of half side ``half_m`` about ``centres`` (a cloud's voxels)."""
    import trimesh

    cube = trimesh.creation.box(extents=(2 * half_m,) * 3)  # 8 corners, 12 triangles facing out
    corners, triangles = np.asarray(cube.vertices), np.asarray(cube.faces)
    vertices = (centres[:, None, :] + corners[None]).reshape(-1, 3)
    faces = (triangles[None] + len(corners) * np.arange(len(centres))[:, None, None]).reshape(-1, 3)
    return vertices, faces


def _clearance_colors(clearance: FloatArray, margin_m: float) -> FloatArray:
    """Colours ``(3, K)`` RGB: red at or below the margin, through yellow, to green at margin + 0.1 m."""
    s = np.clip((clearance - margin_m) / 0.1, 0.0, 1.0)
    return np.vstack([np.where(s < 0.5, 1.0, 2 * (1 - s)), np.where(s < 0.5, 2 * s, 1.0), np.zeros_like(s)])


class _Window(meshcat.visualizer.ViewerWindow):  # type: ignore[misc]
    """meshcat's window, closing the socket it replaces when it connects again.

    meshcat 0.3 connects twice while it starts (to ask for the page's URL) and leaves the
    first socket open until the garbage collector finds it.
    """

    def connect_zmq(self) -> None:
        previous = getattr(self, "zmq_socket", None)
        if previous is not None:
            previous.close(linger=0)
        super().connect_zmq()


class Viewer:
    """A robot among its obstacles in meshcat.

    Args:
        world: the robot among its obstacles (its clearance colours the TCP path).
        margin_m: safety margin drawn as translucent shells [m].
        server: a running server (default: start a loopback one, closed by :meth:`close`).
    """

    def __init__(
        self, world: ck.CollisionWorld, margin_m: float, server: ServerProcess | None = None
    ) -> None:
        robot, obstacles = world.robot, world.obstacles
        self.robot = robot
        self.world = world
        self.margin_m = margin_m
        self._own_server = server is None
        self._carried: list[tuple[CarriedSpan, list[FloatArray]]] = []  # each with its shapes' poses in it
        self.server = server or start_server()
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints the URL; callers decide
            window = _Window(zmq_url=self.server.zmq_url, start_server=False, server_args=[])
            self.vis = meshcat.Visualizer(window=window)
        self._robot_view = MeshcatVisualizer(robot.model, robot.collision_model, robot.visual_model)
        self._robot_view.initViewer(viewer=self.vis, open=False)
        self._robot_view.loadViewerModel(rootNodeName=ROBOT_NODE)
        self._robot_view.displayCollisions(False)
        self._robot_view.displayVisuals(True)
        for obstacle in obstacles:
            pose = obstacle.placement.homogeneous
            for k, (shape, local) in enumerate(_shape_objects(obstacle, 0.0)):
                node = self.vis["scene/obstacles"][obstacle.name][str(k)]
                node.set_object(shape, _material(OBSTACLE_COLOR))
                node.set_transform(pose @ local)
            if margin_m > 0:
                for k, (shape, local) in enumerate(_shape_objects(obstacle, margin_m)):
                    node = self.vis["scene/margin"][obstacle.name][str(k)]
                    node.set_object(shape, _material(OBSTACLE_COLOR, MARGIN_OPACITY))
                    node.set_transform(pose @ local)

    @property
    def url(self) -> str:
        """The page to open in a browser (served on 127.0.0.1)."""
        return self.server.web_url

    def show_geometry(self, visual: bool = True, collision: bool = False) -> None:
        """Toggle the robot's visual and collision geometry."""
        self._robot_view.displayVisuals(visual)
        self._robot_view.displayCollisions(collision)

    def show_configuration(self, q: FloatArray) -> None:
        """Put the robot at configuration ``q`` [rad, m]."""
        self._place(self._robot_view.viewer, q)

    def _place(self, target: Any, q: FloatArray) -> None:
        view = self._robot_view
        previous, view.viewer = view.viewer, target
        try:
            pin.forwardKinematics(view.model, view.data, np.asarray(q, dtype=float))
            view.updatePlacements(pin.GeometryType.VISUAL)
            view.updatePlacements(pin.GeometryType.COLLISION)
        finally:
            view.viewer = previous

    def show_plan(
        self,
        trajectory: Trajectory,
        waypoints: FloatArray,
        samples: int = 400,
        *,
        measured: MeasuredClearance | None = None,
    ) -> dict[str, Any]:
        """Draw the waypoints, the TCP path coloured by clearance and the closest pair.

        The clearance: the world's at each sample, or what the certified checks ``measured``
        (a task's, each segment's in its own world: :mod:`planning.viz.measured_clearance`).
        Returns ``times``, ``tcp`` positions, ``clearance``, the instant of the least
        (``worst_time``) and the ``closest`` pair then: the measuring world's where known.
        """
        times = np.linspace(trajectory.knots[0], trajectory.knots[-1], samples)
        configurations = trajectory(times)
        tcp = ck.frame_positions(self.robot, configurations)
        clearance_of = self.world.clearance_batch
        clearance = clearance_of(configurations).min_clearance_m if measured is None else measured.at(times)
        for i, q in enumerate(np.atleast_2d(waypoints)):
            marker = self.vis["scene/waypoints"][str(i)]
            marker.set_object(g.Sphere(0.015), _material(WAYPOINT_COLOR))
            marker.set_transform(tf.translation_matrix(ck.frame_positions(self.robot, q)))
        finite = np.where(np.isfinite(clearance), clearance, self.margin_m + 1.0)
        path = g.PointsGeometry(tcp.T, color=_clearance_colors(finite, self.margin_m))
        self.vis["scene/tcp_path"].set_object(
            g.Line(path, g.LineBasicMaterial(vertexColors=True, linewidth=3))
        )
        if measured is None or measured.closest is None:
            worst = int(np.argmin(finite))
            worst_time, q_worst = float(times[worst]), configurations[worst]
            closest = self.world.clearance(q_worst).closest
        else:  # found in the world that measured it
            worst_time, closest = measured.worst_time_s, measured.closest
            q_worst = trajectory(worst_time)
        if closest is not None:
            ends = np.column_stack([closest.point_on_robot, closest.point_on_obstacle])
            node = self.vis["scene/closest"]
            node["segment"].set_object(
                g.Line(g.PointsGeometry(ends), g.LineBasicMaterial(color=CLOSEST_COLOR, linewidth=4))
            )
            for name, point in (("robot", closest.point_on_robot), ("obstacle", closest.point_on_obstacle)):
                node[name].set_object(g.Sphere(0.01), _material(CLOSEST_COLOR))
                node[name].set_transform(tf.translation_matrix(point))
        self.show_configuration(q_worst)
        return dict(times=times, tcp=tcp, clearance=clearance, closest=closest, worst_time=worst_time)

    def show_carried(self, trajectory: Trajectory, spans: tuple[CarriedSpan, ...]) -> None:
        """Draw the objects ``trajectory`` carries over ``spans``, each where it is at the start.

        :meth:`animate` then moves each with its frame while it is carried. An object that the
        robot's model carries as its own geometry (the start payload) is drawn only here, so
        that it stays where the trajectory releases it.
        """
        start = np.array([trajectory.knots[0]])
        for span in spans:
            self._forget(span.name)
            pose = carried_poses(self.robot, trajectory, span, start)[0]
            shapes = _shape_objects(span.shape, 0.0)
            for k, (shape, local) in enumerate(shapes):
                node = self.vis["scene/carried"][span.name][str(k)]
                node.set_object(shape, _material(CARRIED_COLOR))
                node.set_transform(pose @ local)
            self._carried.append((span, [local for _, local in shapes]))

    def _forget(self, name: str) -> None:
        """Take geometry ``name`` out of the robot's view (copies of its models: the robot's stay)."""
        view = self._robot_view
        for kind, group in (("visual", "visuals"), ("collision", "collisions")):
            model = getattr(view, f"{kind}_model")
            if model is not None and model.existGeometryName(name):
                model = model.copy()
                model.removeGeometryObject(name)
                setattr(view, f"{kind}_model", model)
                setattr(view, f"{kind}_data", model.createData())
                self.vis[ROBOT_NODE][group][name].delete()

    def animate(self, trajectory: Trajectory, fps: int = 30, repetitions: int = 0) -> int:
        """Record the trajectory at real time (``fps`` frames per second); returns the frame count.

        What :meth:`show_carried` drew moves with it. ``repetitions = 0`` loops forever in the browser.
        """
        animation = Animation(default_framerate=fps)
        count = int(np.ceil(trajectory.duration * fps)) + 1
        times = np.minimum(trajectory.knots[0] + np.arange(count) / fps, trajectory.knots[-1])
        carried = [
            (span.name, carried_poses(self.robot, trajectory, span, times), locals_)
            for span, locals_ in self._carried
        ]
        for frame, t in enumerate(times):
            with animation.at_frame(self.vis, frame) as frame_view:
                self._place(frame_view, trajectory(t))
                for name, poses, locals_ in carried:
                    for k, local in enumerate(locals_):
                        frame_view["scene/carried"][name][str(k)].set_transform(poses[frame] @ local)
        self.vis.set_animation(
            animation, play=True, repetitions=repetitions if repetitions > 0 else 1_000_000
        )
        return count

    def static_html(self) -> str:
        """The whole scene, animation included, as one self-contained HTML page."""
        html: str = self.vis.static_html()
        return html

    def close(self) -> None:
        """Close the connection, and the server if this viewer started it."""
        socket = getattr(self.vis.window, "zmq_socket", None)  # meshcat 0.3's close() is broken
        if socket is not None:
            socket.close(linger=0)
        if self._own_server:
            self.server.close()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
