from __future__ import annotations

import base64
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import psutil
import pytest

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.io.trajectory_io import write_trajectory
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult
from planning.viz.artifacts import viewer_html
from planning.viz.viewer import Viewer
from planning.viz.viewer_server import start_server

from .conftest import PlannedTask

pytestmark = pytest.mark.slow  # every test here starts processes

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--window-size=900,700",
    "--virtual-time-budget=5000",
]


@pytest.fixture(scope="module")
def result(robot: ck.Robot) -> PlanResult:
    return plan(paper_scene(0), robot)


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    pytest.fail("Chromium is needed for the viewer test: apt-get install chromium (.ci/run does)")


def screenshot(html: Path, out: Path, profile: Path) -> np.ndarray:
    command = [
        chromium(),
        *CHROMIUM_FLAGS,
        f"--user-data-dir={profile}",
        f"--screenshot={out}",
        html.as_uri(),
    ]
    subprocess.run(command, capture_output=True, timeout=120, check=True)
    return np.asarray(mpimg.imread(out))[..., :3]


def obstacle_red(image: np.ndarray) -> int:
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((r > 0.6) & (g < 0.4) & (b > 0.2) & (b < 0.45) & (r - g > 0.3)).sum())


def carriage_orange(image: np.ndarray) -> int:
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((r > 0.65) & (g > 0.38) & (g < 0.6) & (b < 0.25)).sum())


def test_exported_html_draws_robot_and_obstacle_in_chromium(
    robot: ck.Robot, result: PlanResult, tmp_path: Path
) -> None:
    scene = result.scene
    page = tmp_path / "viewer.html"
    page.write_text(
        viewer_html(result.problem.world, scene.safety_margin, result.trajectory, result.waypoints)
    )
    text = page.read_text()
    assert "<script" in text and "http://" not in text.split("<script", 1)[1][:200]  # scripts are inline
    image = screenshot(page, tmp_path / "shot.png", tmp_path / "profile")
    assert len(np.unique((image * 255).astype(int).reshape(-1, 3), axis=0)) > 100  # not a blank canvas
    assert obstacle_red(image) > 500
    assert carriage_orange(image) > 50
    # control: the same page without obstacles shows the robot but no obstacle red
    empty = tmp_path / "empty.html"
    empty_world = ck.CollisionWorld(robot, ())
    empty.write_text(viewer_html(empty_world, scene.safety_margin, result.trajectory, result.waypoints))
    control = screenshot(empty, tmp_path / "control.png", tmp_path / "profile2")
    assert obstacle_red(control) < 20
    assert carriage_orange(control) > 50


def test_viewer_scene_contents(robot: ck.Robot, result: PlanResult) -> None:
    with Viewer(result.problem.world, result.scene.safety_margin) as viewer:
        drawn = viewer.show_plan(result.trajectory, result.waypoints)
        frames = viewer.animate(result.trajectory, fps=25)
        html = viewer.static_html()
    assert frames == 101  # 4 s at 25 frames per second, both ends
    closest = drawn["closest"]
    assert closest is not None and closest.obstacle == "crate"
    assert float(np.min(drawn["clearance"])) >= result.scene.safety_margin
    np.testing.assert_allclose(drawn["tcp"][0], (0.5, 0.45, 0.25), atol=1e-9)
    commands = b"".join(base64.b64decode(m) for m in re.findall(r"base64,([A-Za-z0-9+/=]+)", html))
    for path in (
        "scene/obstacles/crate",
        "scene/margin/crate",
        "scene/waypoints/4",
        "scene/tcp_path",
        "scene/closest",
        "/robot",
    ):
        assert path.encode() in commands, path
    assert b"set_animation" in commands


def listening(pid: int) -> list[str]:
    return [
        c.laddr.ip for c in psutil.Process(pid).net_connections(kind="inet") if c.status == psutil.CONN_LISTEN
    ]


def test_server_listens_on_loopback_only_and_stops() -> None:
    server = start_server()
    try:
        addresses = listening(server.process.pid)
        assert len(addresses) == 2 and set(addresses) == {"127.0.0.1"}  # web page and ZeroMQ
        assert server.web_url.startswith("http://127.0.0.1:")
    finally:
        server.close()
    assert server.process.poll() is not None
    assert not psutil.pid_exists(server.process.pid)


def test_show_command_live_and_html(result: PlanResult, tmp_path: Path) -> None:
    trajectory = tmp_path / "trajectory.json"
    write_trajectory(result, trajectory)
    command = [sys.executable, "-m", "planning.cli", "show", str(trajectory)]
    html = subprocess.run(
        [*command, "--html", str(tmp_path / "out.html")], capture_output=True, text=True, check=False
    )
    assert html.returncode == 0 and (tmp_path / "out.html").stat().st_size > 100_000

    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        line = process.stdout.readline()
        assert "meshcat viewer at http://127.0.0.1:" in line
        children = psutil.Process(process.pid).children(recursive=True)
        assert children and all(set(listening(c.pid)) <= {"127.0.0.1"} for c in children)
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=30) == 0
    finally:
        if process.poll() is None:
            process.kill()
    deadline = time.monotonic() + 10
    while (
        any(c.is_running() and c.status() != psutil.STATUS_ZOMBIE for c in children)
        and time.monotonic() < deadline
    ):
        time.sleep(0.1)
    assert not any(c.is_running() and c.status() != psutil.STATUS_ZOMBIE for c in children)


def alive(pid: int) -> bool:
    try:
        return bool(psutil.Process(pid).status() != psutil.STATUS_ZOMBIE)
    except psutil.NoSuchProcess:
        return False


def test_orphaned_server_exits(tmp_path: Path) -> None:
    # a parent that starts a server and dies without closing it: the server follows it
    script = (
        "from planning.viz.viewer_server import start_server; import os; "
        "s = start_server(); print(s.process.pid, flush=True); os._exit(0)"
    )
    completed = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=True
    )
    pid = int(completed.stdout.split()[0])
    deadline = time.monotonic() + 10
    while (
        psutil.pid_exists(pid)
        and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
        and time.monotonic() < deadline
    ):
        time.sleep(0.1)
    assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE


def test_core_imports_no_drawing_libraries() -> None:
    code = "import sys, cpr_kin, planning\nprint(sorted({'meshcat', 'matplotlib'} & set(sys.modules)))"
    completed = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=dict(os.environ)
    )
    assert completed.stdout.strip() == "[]"


def test_a_tasks_page_moves_what_it_carries_and_leaves_it_where_released(
    pick_and_place: PlannedTask, tmp_path: Path
) -> None:
    from planning.viz.artifacts import task_drawn_files

    page = task_drawn_files(pick_and_place.task, plots=False)["viewer.html"]
    assert isinstance(page, str)
    commands = b"".join(base64.b64decode(m) for m in re.findall(r"base64,([A-Za-z0-9+/=]+)", page))
    assert commands.count(b"scene/carried/part") >= 2  # drawn, and a track of the animation
    assert b"set_animation" in commands
    # the robot's own model carries no part: before the attach it rests where it is taken
    assert b"robot/visuals/part" not in commands
    html = tmp_path / "task.html"
    html.write_text(page)
    image = screenshot(html, tmp_path / "task.png", tmp_path / "profile")  # a real browser plays it
    assert len(np.unique((image * 255).astype(int).reshape(-1, 3), axis=0)) > 100  # not a blank canvas
    assert obstacle_red(image) > 500


def test_a_start_payload_released_is_drawn_apart_from_the_robot(robot: ck.Robot, result: PlanResult) -> None:
    from planning.viz.carried_objects import carried_spans

    payload = ck.Payload(mass_kg=0.5, shape=ck.Obstacle.sphere(0.03, (0.0, 0.0, 0.04)), name="ball")
    carrying = ck.carrying(robot, payload)
    spans = carried_spans(payload, [(1.0, None)], result.trajectory.duration)  # released at 1 s
    drawn = []
    for shown in ((), spans):
        with Viewer(ck.CollisionWorld(carrying, ()), 0.1) as viewer:
            viewer.show_carried(result.trajectory, shown)
            viewer.animate(result.trajectory, fps=10)
            html = viewer.static_html()
        drawn.append(b"".join(base64.b64decode(m) for m in re.findall(r"base64,([A-Za-z0-9+/=]+)", html)))
    alone, apart = drawn
    assert b"robot/visuals/ball" in alone and b"scene/carried/ball" not in alone  # the control: on the robot
    # drawn apart, the robot model's own ball gone (it would go on moving with the tool)
    assert b"scene/carried/ball" in apart and b"robot/visuals/ball" not in apart
    assert carrying.collision_model.existGeometryName("ball")  # the robot itself still carries it


def test_a_tasks_path_is_coloured_by_what_its_checks_measured(pick_and_place: PlannedTask) -> None:
    from planning.viz.measured_clearance import task_clearance

    task = pick_and_place.task
    measured = task_clearance(task)
    with Viewer(task.world, task.margin_m) as viewer:
        drawn = viewer.show_plan(task.trajectory, task.junctions, measured=measured)
        own = viewer.show_plan(task.trajectory, task.junctions)  # the drawn world's, without the part
    np.testing.assert_array_equal(drawn["clearance"], measured.at(drawn["times"]))
    # the part, waiting and left behind, comes closer than anything the drawn world alone holds,
    # somewhere on the path: that world would colour it clearer there
    np.testing.assert_array_equal(drawn["times"], own["times"])
    assert (own["clearance"] - drawn["clearance"]).max() > 0.01
    assert drawn["clearance"].min() >= task.margin_m
    # and the closest pair drawn is the one the checks met, found in that segment's world, at
    # the least measured clearance (exact there: coal decides a check's minimum)
    closest = drawn["closest"]
    assert measured.closest is not None and closest.obstacle == measured.closest.obstacle
    assert drawn["worst_time"] == measured.worst_time_s
    assert closest.distance_m == pytest.approx(float(measured.clearance_m.min()), abs=1e-6)
    assert np.linalg.norm(closest.point_on_robot - closest.point_on_obstacle) == pytest.approx(
        closest.distance_m, abs=1e-6
    )
    assert own["closest"].obstacle != "part"  # the drawn world has no part to be close to
