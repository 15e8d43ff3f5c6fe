"""A scene's start and goal as configurations: solved by IK where given as a pose, verified, refused.

:func:`endpoint` gives :func:`~planning.pipeline.problem.build_problem` (and the benchmarks'
validity test, :func:`planning.bench.mbm.endpoint_violations`) the configuration of a start or
goal: a joint vector as it is, a ``tcp`` or ``pose`` by the IK solution the robot reaches
soonest from the seed (:func:`cpr_kin.kinematics.numerical_ik.soonest`) of those clear of the
margins that the motors can hold still. :func:`margin_violation` says
what at a configuration comes inside the safety or self margin.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import PlanningError, TargetOutOfReachError
from planning.pipeline.scene import Scene
from planning.pipeline.torques import check_held, held

FloatArray = NDArray[np.float64]


def margin_violation(world: ck.CollisionWorld, scene: Scene, q: FloatArray) -> str | None:
    """What at ``q`` comes inside the scene's safety or self margin, or ``None`` if nothing does.

    coal's yes/no margin tests decide (:meth:`cpr_kin.CollisionWorld.keeps_clearance`); the
    distances that name the closest pair are measured only where they fail (on a robot of dense
    meshes, the distances of every IK solution tried took most of a plan's build).
    """
    if world.keeps_clearance(q[None], scene.safety_margin, scene.self_margin)[0]:
        return None
    clearance = world.clearance(q)
    closest = clearance.closest
    if closest is not None and clearance.min_clearance_m < scene.safety_margin:
        return (
            f"is inside the safety margin: {closest.robot_geometry} is {clearance.min_clearance_m:.3f} m "
            f"from obstacle '{closest.obstacle}' (margin {scene.safety_margin} m)"
        )
    distance, pair = world.self_collision.distances(q[None])
    if distance[0] < scene.self_margin:
        a, b = world.self_collision.pairs[int(pair[0])]
        coal_m = distance[0] - world.self_collision.allowance_m[int(pair[0])]  # a close pair's own distance
        unlisted = (
            ""
            if world.robot.srdf_path is not None
            else "; no SRDF was found for this URDF: the one listing the pairs its maker lets touch "
            "goes in robot: {srdf: ...}"
        )
        return (
            f"is inside the self margin: {a} is {coal_m:.3f} m from {b} "
            f"(self_margin {scene.self_margin} m; allowed_collisions lets a pair touch{unlisted})"
        )
    return None


def endpoint(
    world: ck.CollisionWorld,
    scene: Scene,
    label: str,
    seed_q: FloatArray | None = None,
    dynamics: ck.Dynamics | None = None,
    preferred: Callable[[FloatArray], bool] | None = None,
) -> FloatArray:
    """The configuration of the scene's start or goal, verified; refused if out of reach or inside a margin.

    A ``tcp`` or ``pose`` is solved by IK (:meth:`~planning.pipeline.target.Target.configuration`):
    the solution nearest ``seed_q`` of those clear of the margins and, with ``dynamics``, that
    the motors can hold still (:func:`~planning.pipeline.torques.check_held`); of those, one
    that passes ``preferred`` where the IK finds one.

    Raises:
        PlanningError: a joint vector of the wrong length, naming the wrong joints or outside
            the ranges; a configuration inside the safety or self margin.
        TargetOutOfReachError: no configuration reaches a ``tcp`` or ``pose`` (its distance named).
        PayloadTooHeavyError: with ``dynamics``, the motors cannot hold the configuration still.
    """
    target = scene.start if label == "start" else scene.goal

    def accepted(q: FloatArray) -> bool:
        if margin_violation(world, scene, q) is not None:
            return False
        return dynamics is None or bool(held(dynamics, q[None])[0])

    try:  # of the clear solutions, those ``preferred`` passes first (none does: the nearest clear one)
        q = target.configuration(world.robot, seed_q, accepted, preferred)
    except ck.IkMissError as exc:
        raise TargetOutOfReachError(f"{label} is out of reach: {exc}") from None
    except ck.CprKinError as exc:
        where = f"{label}.q" if target.q is not None else f"{label} is not reachable"
        raise PlanningError(f"{where}: {exc}") from None
    violation = margin_violation(world, scene, q)
    if violation is not None:
        raise PlanningError(f"{label} q = {np.round(q, 4).tolist()} {violation}")
    if dynamics is not None:
        check_held(dynamics, scene, label, q)
    return q
