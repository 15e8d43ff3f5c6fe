"""A URDF's links form one tree: the check against Pinocchio's parser, and what it names."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
import pytest
from lxml import etree

import cpr_kin as ck
from cpr_kin.description.link_tree import MAX_NAMED, check_tree
from cpr_kin.model.packages import example_robot_data_share

URDF = ck.cpr_urdf_path().read_text()


def test_every_link_of_a_tree_the_check_passes_is_a_frame_of_pinocchios_model(tmp_path: Path) -> None:
    # the oracle: Pinocchio's parser builds every link of a tree; of a closed loop only the
    # root, which is what the loader said before ("no link or frame named 'tcp'")
    share = example_robot_data_share()
    assert share is not None, "example-robot-data is part of the robots extra, which make installs"
    files = sorted((share / "example-robot-data" / "robots").glob("*/*/*.urdf"))
    passed = 0
    for path in [*files, ck.cpr_urdf_path()]:
        try:  # a xacro file, or a robot without a name: not a URDF Pinocchio reads
            model = pin.buildModelFromUrdf(str(path))
        except ValueError:
            continue
        tree = etree.parse(str(path))
        check_tree(tree, path)
        links = {link.get("name") for link in tree.getroot().findall("link")}
        assert links <= {frame.name for frame in model.frames}, path
        passed += 1
    assert passed >= 40
    loop = tmp_path / "loop.urdf"
    loop.write_text(URDF.replace('<parent link="base_link"/>', '<parent link="tool_link"/>'))
    assert "tcp" not in {frame.name for frame in pin.buildModelFromUrdf(str(loop)).frames}
    with pytest.raises(ck.UrdfError, match="close a loop, which hangs from no root link"):
        check_tree(etree.parse(str(loop)), loop)


def test_a_loop_with_no_root_and_a_long_list_are_named_in_short(tmp_path: Path) -> None:
    two = etree.fromstring(
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>'
    )
    with pytest.raises(ck.UrdfError, match=r"joints 'ab' \(a -> b\), 'ba' \(b -> a\) close a loop"):
        check_tree(etree.ElementTree(two), tmp_path / "r.urdf")
    roots = "".join(f'<link name="l{k}"/>' for k in range(MAX_NAMED + 3))
    with pytest.raises(ck.UrdfError, match=r"links 'l0', .* 'l7' and 3 more are each the child of no joint"):
        check_tree(
            etree.ElementTree(etree.fromstring(f'<robot name="r">{roots}</robot>')), tmp_path / "r.urdf"
        )
