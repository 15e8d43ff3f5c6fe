"""``cpr-plan import-moveit``: a MoveIt planning scene and request as a scene file."""

from __future__ import annotations

import argparse

from cpr_kin.common.names import escaped
from cpr_kin.common.user_files import is_yaml_name
from planning.errors import PlanningError
from planning.outcome import EXIT_OK


def cmd_import_moveit(args: argparse.Namespace) -> int:
    """Convert ``args.scene`` and ``args.request`` into the scene file ``args.out``."""
    from planning.io.moveit_import import RobotFiles, import_moveit
    from planning.io.moveit_messages import MotionPlanRequest, PlanningScene, read_message
    from planning.io.moveit_write import write_imported
    from planning.pipeline.scene import MAX_SAFETY_MARGIN_M
    from planning.validation import number_in

    if not is_yaml_name(args.out):
        raise PlanningError(f"--out '{args.out}' must end in .yaml or .yml: a scene file is YAML")
    for flag, value in (("--safety-margin", args.safety_margin), ("--self-margin", args.self_margin)):
        number_in(flag, value, 0.0, MAX_SAFETY_MARGIN_M, unit="m")
    scene = read_message(args.scene, PlanningScene)
    request = read_message(args.request, MotionPlanRequest)
    robot = RobotFiles(
        urdf=args.urdf.resolve(),
        srdf=None if args.srdf is None else args.srdf.resolve(),
        package_dirs=tuple(d.resolve() for d in args.package_dir),
        limits=None if args.limits is None else args.limits.resolve(),
    )
    name = scene.name or args.scene.stem
    imported = import_moveit(scene, request, robot, name, (args.safety_margin, args.self_margin))
    inputs = {
        "PlanningScene file": args.scene,
        "MotionPlanRequest file": args.request,
        "URDF": robot.urdf,
        "SRDF": robot.srdf,
        "joint limits file": robot.limits,
    }
    source = f"the scene converted from '{args.scene}' and '{args.request}'"
    written = write_imported(imported, args.out, inputs, source)
    document = imported.document
    goal = next(iter(document["goal"]))
    print(
        escaped(
            f"wrote {written}: {len(document['obstacles'])} obstacle(s), {len(document['robot']['joints'])} "
            f"planned joints, a '{goal}' goal, {len(document['allowed_collisions'])} allowed link pair(s)"
        )
    )
    if imported.ignored:
        print(escaped("left out or adjusted: " + "; ".join(imported.ignored)))
    return EXIT_OK
