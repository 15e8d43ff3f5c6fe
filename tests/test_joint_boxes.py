"""A geometry's box as a second bound of a pair: exact on an analytic case, below coal's distance, tighter
than the capsules over a squat link."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from cpr_kin.bounds.joint_boxes import box_capsule_bound, joint_boxes
from cpr_kin.bounds.pair_bounds import joint_capsules
from cpr_kin.bounds.segments import segment_distance
from cpr_kin.bounds.self_bounds import SelfPairBounds

# a squat disc on a lift and an arm swinging over it: the disc's capsule (its axis, its radius)
# reaches 0.3 m above it, its box 0.02 m
SQUAT = """<robot name="squat">
  <link name="root"/>
  <joint name="lift" type="prismatic">
    <parent link="root"/><child link="disc"/><origin xyz="0 0.02 0" rpy="0.05 -0.1 0.7"/><axis xyz="0 0 1"/>
    <limit lower="-0.05" upper="0.05" effort="1" velocity="1"/>
  </joint>
  <link name="disc">
    <collision>
      <origin xyz="0.01 0 0" rpy="0 0 0.4"/><geometry><cylinder radius="0.3" length="0.04"/></geometry>
    </collision>
  </link>
  <joint name="swing" type="revolute">
    <parent link="root"/><child link="arm"/><origin xyz="0.05 0 0.15" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <collision>
      <origin xyz="0 0 0.25" rpy="0 0.2 0"/><geometry><box size="0.06 0.04 0.5"/></geometry>
    </collision>
  </link>
</robot>"""


Squat = tuple[pin.Model, pin.GeometryModel]


@pytest.fixture(scope="module")
def squat() -> Squat:
    model = pin.buildModelFromXML(SQUAT)
    return model, pin.buildGeomFromUrdfString(model, SQUAT, pin.COLLISION)


def coal_distances(model: pin.Model, geometry: pin.GeometryModel, q: np.ndarray) -> np.ndarray:
    """Coal's distance [m] between the disc and the arm at each configuration."""
    geometry = geometry.copy()
    geometry.addCollisionPair(pin.CollisionPair(0, 1))
    data, geometry_data = model.createData(), geometry.createData()
    out = []
    for x in q:
        pin.updateGeometryPlacements(model, data, geometry, geometry_data, x)
        out.append(pin.computeDistance(geometry, geometry_data, 0).min_distance)
    return np.array(out)


def capsule_bounds(model: pin.Model, geometry: pin.GeometryModel, q: np.ndarray) -> np.ndarray:
    """The capsules' bound alone [m], placed by Pinocchio (an independent placement)."""
    capsules = joint_capsules(geometry, [0, 1])
    data = model.createData()
    out = []
    for x in q:
        pin.forwardKinematics(model, data, x)
        world = []
        for joint, ends in zip(capsules.joint, capsules.ends, strict=True):
            placement = data.oMi[int(joint) + 1]
            world.append(ends @ placement.rotation.T + placement.translation)
        out.append(segment_distance(world[0], world[1]) - capsules.radius.sum())
    return np.array(out)


def test_the_box_bound_is_the_exact_distance_to_the_box_less_the_radius() -> None:
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # the box turned about z
    boxes = (np.array([-1]), quarter[None], np.array([[0.1, 0.0, 0.0]]), np.array([[0.3, 0.05, 0.02]]))
    joints = (np.zeros((0, 3, 3)), np.zeros((0, 3)))
    above = np.array([[0.1, -0.2, 0.2], [0.1, 0.2, 0.2]])  # over the box's long side (along y now)
    assert box_capsule_bound(0, *joints, boxes, above, 0.05) == pytest.approx(0.2 - 0.02 - 0.05, abs=1e-15)
    beside = np.array([[0.3, 0.0, 0.0], [0.4, 0.0, 0.0]])  # the turned box spans x within 0.05 of 0.1
    assert box_capsule_bound(0, *joints, boxes, beside, 0.01) == pytest.approx(0.3 - 0.15 - 0.01, abs=1e-15)
    reaching = np.array([[0.1, 0.0, 0.06], [0.1, 0.0, 0.3]])  # 0.04 m above it, radius 0.05: no bound
    assert box_capsule_bound(0, *joints, boxes, reaching, 0.05) == -np.inf


def test_the_pair_bound_stays_below_coals_distance_and_clears_what_the_capsules_cannot(squat: Squat) -> None:
    model, geometry = squat
    q = np.random.default_rng(5).uniform(model.lowerPositionLimit, model.upperPositionLimit, (400, 2))
    exact = coal_distances(model, geometry, q)
    capsules = capsule_bounds(model, geometry, q)
    bounds = SelfPairBounds(model, geometry, [(0, 1)])
    np.testing.assert_allclose(bounds(q)[:, 0], capsules, atol=1e-12)  # no threshold: the capsules'
    np.testing.assert_array_equal(bounds.column(q, 0), bounds(q)[:, 0])
    both = bounds(q, 0.5)[:, 0]  # within a threshold, the boxes' too
    np.testing.assert_array_less(both, exact + 1e-9)
    assert np.all(both >= capsules - 1e-12)  # never looser than the capsules
    apart = exact > 0.03
    assert apart.sum() > 100  # the arm clears the disc at most configurations
    assert np.count_nonzero(capsules[apart] > 0.02) == 0  # the disc's capsule never clears it there
    assert np.count_nonzero(both[apart] > 0.02) > 0.8 * apart.sum()  # its box mostly does
    # the blocks' screen says what the pair bounds say
    for threshold in (0.0, 0.02, 0.1):
        expected = bounds(q, threshold)[:, 0] <= threshold
        np.testing.assert_array_equal(bounds.any_below(q, threshold), expected)
        assert not np.any(~expected & (exact <= threshold))  # a pair within the threshold is never cleared


def test_a_boxs_frame_is_its_geometrys_in_its_joints_frame(squat: Squat) -> None:
    _, geometry = squat
    boxes = joint_boxes(geometry, [0, 1])
    assert boxes.joint.tolist() == [0, 1]
    np.testing.assert_allclose(boxes.half, [[0.3, 0.3, 0.02], [0.03, 0.02, 0.25]], atol=1e-12)
    for g in (0, 1):
        placement = geometry.geometryObjects[g].placement
        np.testing.assert_allclose(boxes.axes[g], placement.rotation, atol=1e-15)
        np.testing.assert_allclose(boxes.centre[g], placement.translation, atol=1e-15)


def test_the_box_bound_is_a_sampled_segments_distance_to_the_placed_box() -> None:
    """Random joints, boxes and segments against NumPy's own transforms and a dense sampling."""
    rng = np.random.default_rng(11)
    for _ in range(50):
        rotation = Rotation.random(2, random_state=rng).as_matrix()  # joint 0's, the box's in it
        translation, centre = rng.normal(size=(2, 3))
        half = rng.uniform(0.05, 0.5, 3)
        boxes = (np.array([0]), rotation[1][None], centre[None], half[None])
        segment = rng.normal(scale=2.0, size=(2, 3))
        local = (segment - translation) @ rotation[0] @ rotation[1] - centre @ rotation[1]
        points = local[0] + np.linspace(0.0, 1.0, 20001)[:, None] * (local[1] - local[0])
        sampled = np.linalg.norm(np.maximum(np.abs(points) - half, 0.0), axis=1).min()
        bound = box_capsule_bound(0, rotation[:1], translation[None], boxes, segment, 0.01)
        if sampled > 0.01 + 1e-3:
            assert sampled - 1e-3 <= bound + 0.01 <= sampled + 1e-12
        elif sampled < 0.01 - 1e-3:
            assert bound == -np.inf
