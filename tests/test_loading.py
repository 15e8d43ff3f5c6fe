"""Robots no one here wrote, from example-robot-data: they load, and their kinematics agree with yourdfpy.

Each robot is loaded as a user would (``cpr_kin.load_robot(urdf)``: meshes by ``package://``,
the arm's joints planned, the rest held). Forward kinematics of every link is compared with
yourdfpy's, an independent URDF reader, at random configurations.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from re import escape as re_escape
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

import cpr_kin as ck
from cpr_kin.description.resources import makers_limits_path
from cpr_kin.description.robot_options import SHOWN_LINKS
from cpr_kin.model import packages
from cpr_kin.model.packages import example_robot, example_robot_data_share

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"

FINGERS = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
ARMS = {
    "so101": (ROBOTS / "so_arm_description/urdf/so101.urdf", 5, {"gripper": 0.0}),  # the jaw held
    "ur5": (ROBOTS / "ur_description/urdf/ur5_robot.urdf", 6, {}),
    "panda": (ROBOTS / "panda_description/urdf/panda.urdf", 7, FINGERS),
    "xarm7": (ROBOTS / "xarm_description/urdf/xarm7.urdf", 7, {}),
}


@pytest.fixture(scope="module", params=sorted(ARMS))
def arm(request: pytest.FixtureRequest) -> tuple[str, ck.Robot, Path]:
    urdf, _, _ = ARMS[request.param]
    return request.param, ck.load_robot(urdf), urdf


def test_the_arm_is_planned_and_the_hand_held(arm: tuple[str, ck.Robot, Path]) -> None:
    name, robot, _ = arm
    _, dof, held = ARMS[name]
    assert robot.nq == dof and dict(robot.held) == held
    if name == "panda":  # Franka's datasheet, shipped for a URDF named "panda"
        assert (
            robot.limits_path == makers_limits_path("panda", robot.joint_names) and not robot.limits_defaulted
        )
    else:
        assert robot.limits_path is None and robot.limits_defaulted == robot.joint_names  # no limits file
    assert robot.limits.effort is not None and np.all(robot.limits.effort > 0)  # kept for the torque issue
    assert robot.model.existFrame(robot.tcp_frame)
    assert {g.group for g in robot.geometries} == set(ck.GROUPS)


TOOLS = {"so101": "gripper_frame_link", "ur5": "tool0", "panda": "panda_hand_tcp", "xarm7": "link_eef"}
"""The tool frames the makers' URDFs define: a bare fixed leaf beside a jaw or a collision box."""


def test_the_tool_is_the_makers_tool_frame(arm: tuple[str, ck.Robot, Path]) -> None:
    name, robot, _ = arm
    assert robot.tcp_frame == TOOLS[name]
    links = {g.link for g in robot.geometries if g.group == "effector"}
    assert links and not links & {"base_link", "shoulder_link", "panda_link1", "link1"}


def test_forward_kinematics_agrees_with_yourdfpy(arm: tuple[str, ck.Robot, Path]) -> None:
    name, robot, urdf = arm
    reference = yourdfpy.URDF.load(str(urdf), build_scene_graph=True, load_meshes=False)
    links = [f.name for f in robot.model.frames if f.type.name == "BODY"]
    rng = np.random.default_rng(7)
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, (20, robot.nq)):
        configuration = dict(zip(robot.joint_names, q, strict=True)) | dict(robot.held)
        reference.update_cfg({k: v for k, v in configuration.items() if k in reference.actuated_joint_names})
        ours = ck.frame_poses(robot, np.tile(q, (1, 1)), None)  # the tool frame, batch of one
        for link in links:
            theirs = reference.get_transform(frame_to=link)
            mine = ck.frame_poses(robot, q, link)
            np.testing.assert_allclose(mine[:3, 3], theirs[:3, 3], atol=1e-9, err_msg=f"{name}: {link}")
            np.testing.assert_allclose(mine[:3, :3], theirs[:3, :3], atol=1e-9, err_msg=f"{name}: {link}")
        assert ours.shape == (1, 4, 4)


def test_meshes_are_convex_hulls_that_contain_them() -> None:
    import coal
    import trimesh

    robot = ck.load_robot(ARMS["panda"][0])
    checked = 0
    for obj in robot.collision_model.geometryObjects:
        assert not isinstance(obj.geometry, coal.BVHModelBase)  # every mesh became its hull
        if isinstance(obj.geometry, coal.Convex) and obj.meshPath:
            mesh: Any = trimesh.load(obj.meshPath, force="mesh")
            hull = trimesh.Trimesh(np.asarray(obj.geometry.points())).convex_hull  # coal's hull points
            vertices = mesh.vertices * np.asarray(obj.meshScale)
            # every vertex of the mesh is inside the hull or on it (trimesh: > 0 inside)
            assert (hull.nearest.signed_distance(vertices) > -1e-6).all(), obj.name
            checked += 1
    assert checked >= 8


def test_example_robot_data_is_found_where_its_distribution_lists_its_package() -> None:
    from importlib import metadata

    distribution = metadata.distribution("example-robot-data")
    listed = [f for f in distribution.files or () if str(f).endswith("example-robot-data/package.xml")]
    assert len(listed) == 1
    share = example_robot_data_share()
    assert share == Path(str(listed[0].locate())).resolve().parent.parent
    assert (share / "example-robot-data" / "robots").is_dir()


def test_a_mesh_that_is_nowhere_is_named(tmp_path: Path) -> None:
    text = ARMS["xarm7"][0].read_text().replace("xarm7/visual/link1.stl", "xarm7/visual/no_such.stl")
    urdf = tmp_path / "xarm7.urdf"
    urdf.write_text(text)
    missing = "package://example-robot-data/robots/xarm_description/meshes/xarm7/visual/no_such.stl"
    with pytest.raises(ck.UrdfError, match=f"mesh '{missing}' not found"):
        ck.load_robot(urdf)


def test_package_dirs_are_looked_in_first(tmp_path: Path) -> None:
    # a copy of the xArm's description under another name, found through package_dirs
    text = ARMS["xarm7"][0].read_text().replace("package://example-robot-data/robots/", "package://my_arms/")
    urdf = tmp_path / "urdf" / "xarm7.urdf"
    urdf.parent.mkdir()
    urdf.write_text(text)
    with pytest.raises(ck.UrdfError, match="package 'my_arms' is in none of"):
        ck.load_robot(urdf)
    (tmp_path / "share").mkdir()
    (tmp_path / "share" / "my_arms").symlink_to(ROBOTS)
    robot = ck.load_robot(urdf, package_dirs=[tmp_path / "share"])
    assert robot.nq == 7
    # a folder that is not there is named, not passed over (the meshes may be found anyway)
    with pytest.raises(ck.UrdfError, match=r"package folder '.*shared' \(packages, .*\) does not exist"):
        ck.load_robot(urdf, package_dirs=[tmp_path / "shared", tmp_path / "share"])
    with pytest.raises(ck.UrdfError, match=r"package folder '.*xarm7.urdf' .* is not a folder"):
        ck.load_robot(urdf, package_dirs=[urdf])


def test_a_urdf_that_names_no_package_looks_for_none(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # example-robot-data is found by a search of every installed distribution: only where asked
    def not_asked() -> Path:
        raise AssertionError("example-robot-data looked up for a URDF that names no package")

    urdf = panda_copy(tmp_path, lambda text: text)  # every mesh a file:// path
    monkeypatch.setattr(packages, "example_robot_data_share", not_asked)
    assert ck.load_robot(urdf).nq == 7
    with pytest.raises(ck.UrdfError, match=r"package folder '.*nowhere' \(packages, .*\) does not exist"):
        ck.load_robot(urdf, package_dirs=[tmp_path / "nowhere"])  # a folder given is checked all the same
    with pytest.raises(AssertionError, match="looked up"):  # a package:// mesh looks there
        ck.load_robot(ARMS["so101"][0])


def test_planned_and_held_joints_are_checked() -> None:
    panda = ARMS["panda"][0]
    with pytest.raises(ck.UrdfError, match=r"has no joint\(s\) \['elbow'\]"):
        ck.load_robot(panda, joints=["elbow"])
    with pytest.raises(ck.UrdfError, match="mimic another; they cannot be planned"):
        ck.load_robot(panda, joints=[*(f"panda_joint{k}" for k in range(1, 8)), "panda_finger_joint2"])
    with pytest.raises(ck.UrdfError, match=r"held joint 'panda_finger_joint1' = 0.5 is outside \[0, 0.04\]"):
        ck.load_robot(panda, held={"panda_finger_joint1": 0.5})
    opened = ck.load_robot(panda, held={"panda_finger_joint1": 0.04})
    assert dict(opened.held) == {
        "panda_finger_joint1": 0.04,
        "panda_finger_joint2": 0.04,
    }  # the mimic follows


def panda_copy(folder: Path, edit: Callable[[str], str]) -> Path:
    """The Panda's URDF edited, under another robot name (so no maker's limits file), meshes in place."""
    text = ARMS["panda"][0].read_text().replace("package://example-robot-data/robots/", f"file://{ROBOTS}/")
    urdf = folder / "arm.urdf"
    urdf.write_text(edit(text.replace('<robot name="panda"', '<robot name="my_arm"', 1)))
    return urdf


def test_a_mimic_of_a_joint_the_urdf_lacks_is_named_and_holding_the_joint_loads(tmp_path: Path) -> None:
    # alex_psyonic_hands.urdf's fingers mimic 'index_q1', a joint it does not have: an IndexError
    urdf = panda_copy(
        tmp_path, lambda t: t.replace('<mimic joint="panda_finger_joint1"', '<mimic joint="nope"')
    )
    with pytest.raises(
        ck.UrdfError, match=r"joint 'panda_finger_joint2' mimics joint 'nope', which the URDF does not have"
    ):
        ck.load_robot(urdf)
    held = ck.load_robot(urdf, held={"panda_finger_joint2": 0.01})
    assert dict(held.held) == {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.01}


def test_a_continuous_joint_without_limits_is_held_but_not_planned(tmp_path: Path) -> None:
    # the URDF specification leaves a continuous joint's <limit> out; tiago_dual.urdf's caster
    # wheels have none, and the whole robot was refused for them
    def free_wrist(text: str) -> str:
        start = text.index('<joint name="panda_joint7" type="revolute">')
        limit_at = text.index("<limit", start)
        limit_end = text.index("/>", limit_at) + 2
        edited = text[:limit_at] + text[limit_end:]
        return edited.replace(
            '<joint name="panda_joint7" type="revolute">', '<joint name="panda_joint7" type="continuous">'
        )

    urdf = panda_copy(tmp_path, free_wrist)
    with pytest.raises(ck.UrdfError, match=r"joint\(s\) \['panda_joint7'\] have no velocity limit"):
        ck.load_robot(urdf)
    arm = [f"panda_joint{k}" for k in range(1, 7)]
    robot = ck.load_robot(urdf, joints=arm, held={"panda_joint7": 0.3})
    assert robot.joint_names == tuple(arm) and dict(robot.held)["panda_joint7"] == 0.3
    with pytest.raises(ck.UrdfError, match=r"held joint 'panda_joint7' = 7 is outside \[-6.28319, 6.28319\]"):
        ck.load_robot(urdf, joints=arm, held={"panda_joint7": 7.0})  # one turn either way, as a planned one


def test_a_tool_without_collision_geometry_leaves_the_effector_group_to_the_link_above() -> None:
    so100 = ck.load_robot(ROBOTS / "so_arm_description/urdf/so100.urdf")  # gripper and jaw: visual only
    assert {g.link for g in so100.geometries if g.group == "effector"} == {"wrist"}
    assert {g.group for g in so100.geometries} == set(ck.GROUPS)


def urdf_joints_to(urdf: Path, link: str) -> list[str]:
    """The moving joints from the URDF's root down to ``link``, read from the XML alone (the oracle)."""
    from lxml import etree

    into = {j.find("child").get("link"): j for j in etree.parse(str(urdf)).getroot().findall("joint")}
    joints: list[str] = []
    while link in into:
        joint = into[link]
        if joint.get("type") != "fixed" and joint.find("mimic") is None:
            joints.append(joint.get("name"))
        link = joint.find("parent").get("link")
    return joints[::-1]


@pytest.mark.parametrize(
    ("urdf", "tool", "branches"),
    [
        (
            "pr2_description/urdf/pr2.urdf",
            "r_gripper_tool_frame",
            "'r_shoulder_pan_link', 'l_shoulder_pan_link'",
        ),
        ("baxter_description/urdf/baxter.urdf", "right_gripper", "'right_arm_mount', 'left_arm_mount'"),
    ],
)
def test_a_robot_of_several_arms_plans_the_joints_to_the_tool_it_is_given(
    urdf: str, tool: str, branches: str
) -> None:
    with pytest.raises(
        ck.UrdfError, match=rf"has no single arm: its tree branches .*{branches}.*name the tool"
    ):
        ck.load_robot(ROBOTS / urdf)
    robot = ck.load_robot(ROBOTS / urdf, tcp=tool)
    assert list(robot.joint_names) == urdf_joints_to(ROBOTS / urdf, tool) and robot.nq >= 7
    assert robot.tcp_frame == tool


def test_a_tool_the_urdf_lacks_is_named_not_taken_for_no_tool() -> None:
    # on a tree of several arms a misspelt tcp used to read "has no single arm ... name the
    # tool frame", as if none had been given
    with pytest.raises(
        ck.UrdfError,
        match=r"has no link or frame named 'r_gripper_tool' \(the tool frame, tcp\); "
        r"did you mean .*'r_gripper_tool_frame'",
    ):
        ck.load_robot(ROBOTS / "pr2_description/urdf/pr2.urdf", tcp="r_gripper_tool")


def test_a_missing_tool_frame_lists_the_first_links_and_counts_the_rest() -> None:
    urdf = ROBOTS / "romeo_description/urdf/romeo.urdf"
    model = pin.buildModelFromUrdf(str(urdf))
    links = sorted({f.name for f in model.frames if f.type == pin.FrameType.BODY})
    assert len(links) > SHOWN_LINKS  # a humanoid: more links than a message lists
    with pytest.raises(ck.UrdfError) as refused:
        ck.load_robot(urdf, tcp="LWristPitchLink")
    message = str(refused.value)
    assert "did you mean 'LWristPitch'" in message
    shown = ", ".join(f"'{link}'" for link in links[:SHOWN_LINKS])
    assert f"its links are {shown} and {len(links) - SHOWN_LINKS} more" in message
    assert message.endswith(" more")  # the rest counted, not listed


def test_a_missing_tool_frame_is_never_offered_pinocchios_root() -> None:
    # 'nowhere' is closest to 'universe', the root frame Pinocchio adds and no URDF names
    with pytest.raises(ck.UrdfError) as refused:
        ck.load_robot(example_robot("ur5"), tcp="nowhere")
    assert "universe" not in str(refused.value) and "no link or frame named 'nowhere'" in str(refused.value)


def test_a_urdf_without_collision_shapes_is_refused_naming_the_fix() -> None:
    with pytest.raises(
        ck.UrdfError, match=r"has no <collision> geometry: .*give the links <collision> elements"
    ):
        ck.load_robot(ROBOTS / "asr_twodof_description" / "urdf" / "TwoDofs.urdf")


def test_effector_links_without_shapes_are_refused_naming_them() -> None:
    with pytest.raises(
        ck.UrdfError,
        match=r"no collision geometry in group 'effector' .*name links that have shapes in effector_links "
        r"\(now \['tool0'\]\)",
    ):
        ck.load_robot(example_robot("ur5"), effector_links=("tool0",))


def test_a_tool_named_as_a_joint_and_a_link_is_the_link() -> None:
    # the B1-Z1 names a fixed joint and its child link 'gripperStator': Pinocchio's
    # getFrameId refused to choose (a ValueError, not a message); the link's frame is taken
    b1_description = ROBOTS / "b1_description"
    robot = ck.load_robot(
        b1_description / "urdf" / "b1-z1.urdf",
        tcp="gripperStator",
        srdf=b1_description / "srdf" / "b1-z1.srdf",
    )
    assert robot.joint_names == tuple(f"joint{k}" for k in range(1, 7))  # the arm's, not the legs'
    frames = [f for f in robot.model.frames if f.name == "gripperStator"]
    assert {f.type for f in frames} == {pin.FrameType.BODY, pin.FrameType.FIXED_JOINT}
    chosen = robot.model.frames[robot.frame_id("gripperStator")]
    assert chosen.type == pin.FrameType.BODY
    assert all(f.placement.isApprox(chosen.placement) for f in frames)  # one place either way


@pytest.mark.parametrize(
    ("urdf", "tcp"),
    [
        ("anymal_c_simple_description/urdf/anymal.urdf", "LF_FOOT"),
        ("b1_description/urdf/b1-z1.urdf", "gripperMover"),
    ],
)
def test_joints_named_as_links_are_held_and_planned_as_the_urdf_says(urdf: str, tcp: str) -> None:
    # ANYmal's joint and link 'LF_HAA', the B1-Z1's fixed joint and link 'gripperStator': Pinocchio's
    # reduction to the planned joints refused two frames of one name (a ValueError, an internal error)
    robot = ck.load_robot(ROBOTS / urdf, tcp=tcp)
    reference = yourdfpy.URDF.load(str(ROBOTS / urdf), build_scene_graph=True, load_meshes=False)
    links = [f.name for f in robot.model.frames if f.type == pin.FrameType.BODY]
    assert set(robot.model.names[1:]) == set(robot.joint_names)  # the names given back
    rng = np.random.default_rng(11)
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, (10, robot.nq)):
        configuration = dict(zip(robot.joint_names, q, strict=True)) | dict(robot.held)
        reference.update_cfg({k: v for k, v in configuration.items() if k in reference.actuated_joint_names})
        for link in links:
            np.testing.assert_allclose(
                ck.frame_poses(robot, q, link),
                reference.get_transform(frame_to=link),
                atol=1e-9,
                err_msg=link,
            )
    assert robot.visual_model.ngeoms > 0  # reduced the same way


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"joints": "panda_joint1"}, r"joints = 'panda_joint1' must be a sequence, not one name"),
        ({"package_dirs": "/tmp"}, r"package_dirs = '/tmp' must be a sequence, not one name"),
        ({"tcp": 7}, r"tcp = 7 must be a frame's name"),
        ({"joints": ["panda_joint1", 2]}, r"joints = \('panda_joint1', 2\) must be a sequence of names"),
        ({"held": {"panda_finger_joint1": "open"}}, r"held = .* must map joint names to numbers"),
    ],
)
def test_options_of_the_wrong_kind_are_named(options: dict[str, Any], message: str) -> None:
    # a string of joint names was split into letters, an int tcp reached Pinocchio's C++ signature
    with pytest.raises(ck.UrdfError, match=message):
        ck.load_robot(example_robot("panda"), **options)


def test_fixed_joints_and_mimics_in_the_options_are_named_as_such() -> None:
    panda, arm = ARMS["panda"][0], [f"panda_joint{k}" for k in range(1, 8)]
    with pytest.raises(ck.UrdfError, match=r"joints names fixed joint\(s\) \['panda_joint8'\]; its movable"):
        ck.load_robot(panda, joints=[*arm, "panda_joint8"])
    with pytest.raises(ck.UrdfError, match=r"held names fixed joint\(s\) \['panda_hand_joint'\]"):
        ck.load_robot(panda, held={"panda_hand_joint": 0.0})
    # a mimic held at a value its <mimic> contradicts: refused, naming the leader to hold instead
    with pytest.raises(
        ck.UrdfError,
        match=r"held joint 'panda_finger_joint2' = 0.03 mimics 'panda_finger_joint1' = 0 "
        r".*hold 'panda_finger_joint1'",
    ):
        ck.load_robot(panda, held={"panda_finger_joint2": 0.03})
    agreeing = ck.load_robot(panda, held={"panda_finger_joint1": 0.03, "panda_finger_joint2": 0.03})
    assert dict(agreeing.held) == {"panda_finger_joint1": 0.03, "panda_finger_joint2": 0.03}


def test_a_joint_map_naming_a_held_joint_says_it_is_held() -> None:
    panda = ck.load_robot(ARMS["panda"][0])
    values = {name: 0.0 for name in panda.joint_names} | {"panda_finger_joint1": 0.0}
    with pytest.raises(
        ck.JointLimitError, match=r"\['panda_finger_joint1'\] are held \(fixed\), not planned"
    ):
        panda.configuration(values)


def test_a_mesh_that_is_not_a_mesh_names_its_link_and_file(tmp_path: Path) -> None:
    (tmp_path / "link3.stl").write_text("a text file, not a mesh\n")
    urdf = panda_copy(
        tmp_path,
        lambda t: t.replace(
            f"file://{ROBOTS}/panda_description/meshes/collision/link3.stl", str(tmp_path / "link3.stl")
        ),
    )
    with pytest.raises(ck.UrdfError) as info:
        ck.load_robot(urdf)
    message = str(info.value)
    assert f"link 'panda_link3': mesh '{tmp_path / 'link3.stl'}' is not a mesh file coal can read" in message
    assert ".cpp" not in message and len(message.replace(str(tmp_path), "")) < 250  # no C++ source named


@pytest.mark.parametrize(("value", "shown"), [(".nan", "nan"), ("-5", "-5"), (".inf", "inf")])
def test_a_limits_file_value_that_is_no_positive_number_names_the_file_and_joint(
    tmp_path: Path, value: str, shown: str
) -> None:
    limits = tmp_path / "limits.yaml"
    limits.write_text(f"panda_joint3: {{acceleration: {value}, jerk: 100}}\n")
    with pytest.raises(
        ck.UrdfError,
        match=rf"joint limits file '{limits}': joint 'panda_joint3' acceleration = {shown} "
        "must be a finite number > 0",
    ):
        ck.load_robot(ARMS["panda"][0], limits=limits)


def test_a_zero_velocity_of_an_installed_urdf_suggests_a_limits_file_only(tmp_path: Path) -> None:
    from cpr_kin.model.packages import installed

    def stopped(text: str) -> str:
        return text.replace('velocity="2.175"', 'velocity="0"', 1)

    own = panda_copy(tmp_path, stopped)
    with pytest.raises(ck.UrdfError, match=r"give <limit velocity=\.\.\.> in the URDF, or 'velocity' in"):
        ck.load_robot(own)
    assert installed(ARMS["panda"][0]) and not installed(own)
    # the installed URDF's own zero: a limits file is the only thing the user should edit
    from cpr_kin.model.limits import read_dynamic_limits

    with pytest.raises(ck.UrdfError) as info:
        read_dynamic_limits(None, ("panda_joint1",), np.zeros(1), urdf=ARMS["panda"][0])
    assert "in the URDF" not in str(info.value) and "'velocity' in a limits file (limits=...)" in str(
        info.value
    )


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("<html><body>a page</body></html>", "has root element <html>; an SRDF's is <robot>"),
        (None, "holds <link> or <joint> elements: it is a URDF"),
    ],
)
def test_an_srdf_that_is_no_srdf_is_refused(tmp_path: Path, content: str | None, message: str) -> None:
    srdf = tmp_path / "panda.srdf"
    srdf.write_text(content if content is not None else ARMS["panda"][0].read_text())
    with pytest.raises(ck.UrdfError, match=re_escape(message)):
        ck.load_robot(ARMS["panda"][0], srdf=srdf)


@pytest.mark.parametrize("ups", [1, 8, 20])
def test_a_package_path_that_leaves_its_package_is_refused(tmp_path: Path, ups: int) -> None:
    escape = "package://example-robot-data/" + "../" * ups + "etc/hostname"
    urdf = panda_copy(
        tmp_path,
        lambda t: t.replace(f"file://{ROBOTS}/panda_description/meshes/collision/link3.stl", escape),
    )
    with pytest.raises(
        ck.UrdfError, match=re_escape(f"mesh '{escape}' leaves its package 'example-robot-data'")
    ):
        ck.load_robot(urdf)
    inside = panda_copy(  # a path that goes up and back in stays inside: loaded
        tmp_path,
        lambda t: t.replace(
            f"file://{ROBOTS}/panda_description/meshes/collision/link3.stl",
            "package://example-robot-data/robots/panda_description/../panda_description/meshes/collision/link3.stl",
        ),
    )
    assert ck.load_robot(inside).nq == 7


def test_an_srdf_given_as_the_urdf_is_named_as_such() -> None:
    srdf = ARMS["panda"][0].parents[1] / "srdf" / "panda.srdf"
    with pytest.raises(
        ck.UrdfError, match="holds <group>s and no <link>: it is an SRDF; give the robot's URDF"
    ):
        ck.load_robot(srdf)


FLAT_ARM = """<?xml version="1.0"?>
<robot name="flat_arm">
  <link name="base"><collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision></link>
  <link name="arm">
    <collision><origin xyz="0.1 0 0"/><geometry><mesh filename="plate.stl"/></geometry></collision>
  </link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="tip" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0.2 0 0"/></joint>
</robot>
"""


@pytest.mark.parametrize(
    ("joint_type", "tcp", "message"),
    [
        (
            "fixed",
            None,
            r"has no joint to plan: .*\(its moving joints: \[\]\); give the robot a joint",
        ),
        (
            "revolute",
            "base",
            r"between its root and the tool frame 'base': .*name a tool frame the joints move",
        ),
    ],
)
def test_a_robot_with_no_joint_to_plan_is_named_as_such(
    tmp_path: Path, joint_type: str, tcp: str | None, message: str
) -> None:
    # before, the first error named a collision group ("no collision geometry in group 'links'")
    box_arm = FLAT_ARM.replace('<mesh filename="plate.stl"/>', '<box size="0.2 0.05 0.05"/>')
    (tmp_path / "arm.urdf").write_text(box_arm.replace('type="revolute"', f'type="{joint_type}"'))
    with pytest.raises(ck.UrdfError, match=message):
        ck.load_robot(tmp_path / "arm.urdf", tcp=tcp)
    if tcp is not None:  # the same arm to its own tool plans its joint
        assert ck.load_robot(tmp_path / "arm.urdf", tcp="tool").joint_names == ("j1",)


def test_a_link_whose_mesh_is_flat_loads_as_its_capsule_and_its_mesh_decides(tmp_path: Path) -> None:
    # a plate of no thickness: coal's Qhull crashed the process (a segmentation fault) on its hull
    import trimesh

    trimesh.creation.box(extents=(0.2, 0.1, 0.0)).export(tmp_path / "plate.stl")
    (tmp_path / "flat_arm.urdf").write_text(FLAT_ARM)
    robot = ck.load_robot(tmp_path / "flat_arm.urdf", tcp="tool")
    assert len(robot.capsule_meshes) == 1 and len(robot.exact_meshes) == 1
    # a ball 2 cm above the plate's middle (at q = 0 the plate lies at z = 0.1 m, x in [0, 0.2] m),
    # inside the capsule about it: the plate's own mesh says how far it is
    ball = ck.Obstacle.sphere(0.01, (0.1, 0.0, 0.13))
    world = ck.CollisionWorld(robot, [ball])
    q = np.zeros((1, robot.nq))
    assert not world.margin_violated(q, 0.015)[0] and world.margin_violated(q, 0.025)[0]
    assert world.min_clearance_batch(q)[0][0] == pytest.approx(0.02, abs=1e-5)


def with_a_vertex(path: Path, vertex: tuple[float, float, float]) -> None:
    """A binary STL of a 20 x 10 x 5 cm box at ``path``, its first triangle's first vertex ``vertex``."""
    import struct

    import trimesh

    data = bytearray(trimesh.exchange.stl.export_stl(trimesh.creation.box(extents=(0.2, 0.1, 0.05))))
    data[84 + 12 : 84 + 24] = struct.pack("<3f", *vertex)  # 80 header, 4 count, then 12 normal
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("value", [np.inf, -np.inf, np.nan])
def test_a_mesh_with_a_vertex_not_finite_is_refused_naming_link_and_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], value: float
) -> None:
    # coal crashed the process (a segmentation fault) on the hull of an infinite vertex
    with_a_vertex(tmp_path / "plate.stl", (0.1, value, 0.02))
    (tmp_path / "flat_arm.urdf").write_text(FLAT_ARM)
    with pytest.raises(ck.UrdfError, match=r"link 'arm': mesh '.*plate.stl' has a vertex that is not finite"):
        ck.load_robot(tmp_path / "flat_arm.urdf", tcp="tool")
    from planning.cli import main

    assert main(["robot-info", str(tmp_path / "flat_arm.urdf"), "--tcp", "tool"]) == 2
    stderr = capsys.readouterr().err
    assert "not finite" in stderr and stderr.count("\n") == 1 and "Traceback" not in stderr


def test_a_mesh_in_millimetres_without_its_scale_is_refused_and_loads_with_it(tmp_path: Path) -> None:
    import trimesh

    trimesh.creation.box(extents=(200.0, 100.0, 50.0)).export(tmp_path / "plate.stl")  # millimetres
    (tmp_path / "flat_arm.urdf").write_text(FLAT_ARM)
    reach = float(np.linalg.norm([100.0, 50.0, 25.0]))
    with pytest.raises(
        ck.UrdfError, match=rf"mesh '.*plate.stl' reaches {reach:.6g} m .* beyond 100 m.*0\.001"
    ):
        ck.load_robot(tmp_path / "flat_arm.urdf", tcp="tool")
    scaled = FLAT_ARM.replace('filename="plate.stl"', 'filename="plate.stl" scale="0.001 0.001 0.001"')
    (tmp_path / "scaled_arm.urdf").write_text(scaled)
    robot = ck.load_robot(tmp_path / "scaled_arm.urdf", tcp="tool")
    (hull,) = (o.geometry for o in robot.collision_model.geometryObjects if o.name == "arm")
    assert np.abs(np.asarray(hull.points(), dtype=float)).max(axis=0) == pytest.approx([0.1, 0.05, 0.025])


@pytest.mark.parametrize(
    ("scale", "message"),
    [
        ("0 0 0", r"link 'arm': collision mesh scale = '0 0 0' is not supported; give three finite numbers"),
        ("1e-9 1e-9 1e-9", r"link 'arm': mesh '.*plate.stl' spans 2e-10 m .* below 1e-06 m"),
    ],
)
def test_a_mesh_scaled_below_a_micrometre_is_refused(tmp_path: Path, scale: str, message: str) -> None:
    # at 1e-9 trimesh merged the box's corners into one point and SciPy's Qhull raised: a bug's exit
    import trimesh

    trimesh.creation.box(extents=(0.2, 0.1, 0.05)).export(tmp_path / "plate.stl")
    scaled = FLAT_ARM.replace('filename="plate.stl"', f'filename="plate.stl" scale="{scale}"')
    (tmp_path / "arm.urdf").write_text(scaled)
    with pytest.raises(ck.UrdfError, match=message):
        ck.load_robot(tmp_path / "arm.urdf", tcp="tool")
