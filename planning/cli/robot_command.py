"""``cpr-plan robot-info``: what the planner makes of a robot, its shapes measured against its meshes."""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
from typing import Any

import cpr_kin as ck
from cpr_kin.common.names import escaped
from cpr_kin.common.user_files import is_yaml_name
from planning.io import json_layout
from planning.outcome import EXIT_OK


def robot_report(robot: ck.Robot) -> dict[str, Any]:
    """The robot as the planner loaded it: files, joints and limits, tool, shapes, pairs (JSON-ready)."""
    from cpr_kin.model.hull_excess import SAMPLES, shape_excess

    limits = robot.limits
    return {
        "urdf": str(robot.urdf_path),
        "srdf": None if robot.srdf_path is None else str(robot.srdf_path),
        "srdf_unknown_links": list(robot.srdf_unknown_links),
        "limits_file": None if robot.limits_path is None else str(robot.limits_path),
        "limits_defaulted": list(robot.limits_defaulted),
        "joints": [
            {
                "name": name,
                "unit": robot.joint_unit(name),
                "lower": float(limits.lower[k]),
                "upper": float(limits.upper[k]),
                "velocity": float(limits.velocity[k]),
                "acceleration": float(limits.acceleration[k]),
                "jerk": float(limits.jerk[k]),
                # the URDF's range where it passes one turn either way (planned within it), else None
                "urdf_range": list(robot.ranges_narrowed[name]) if name in robot.ranges_narrowed else None,
            }
            for k, name in enumerate(limits.names)
        ],
        "held": dict(robot.held),
        "base_joints": list(robot.base_joints),
        "tcp_frame": robot.tcp_frame,
        "excess_samples": SAMPLES,
        "shapes": [
            {
                "geometry": s.geometry,
                "link": s.link,
                "kind": s.kind,
                "mesh": s.mesh,
                "excess_m": s.excess_m,
                "spacing_m": s.spacing_m,
                "bound_excess_m": None if math.isnan(s.bound_excess_m) else s.bound_excess_m,
            }
            for s in shape_excess(robot)
        ],
        "self_pairs_checked": len(robot.self_pairs),
        "touching_by_design": [list(pair) for pair in robot.overlapping_links],
        "close_by_design": [{"links": list(c.links), "largest_m": c.largest_m} for c in robot.close_pairs],
    }


def cmd_robot_info(args: argparse.Namespace) -> int:
    """Print what the planner makes of ``args.robot``: a scene's ``robot:`` value, or a scene file.

    ``--tcp``, ``--srdf`` and ``--package-dir`` are the keys ``tcp``, ``srdf`` and ``packages`` of a
    scene's ``robot:`` mapping: a robot whose tree branches (a humanoid, a mobile manipulator)
    loads only with its tool frame named.
    """
    from planning.io.robot_entry import robot_spec_of
    from planning.io.scene_file import scene_robot

    # a scene file: the robot it names, as a plan of it loads it
    spec = scene_robot(args.robot) if is_yaml_name(args.robot) else robot_spec_of(args.robot, Path.cwd())
    named = {
        "tcp": args.tcp,
        "srdf": None if args.srdf is None else args.srdf.resolve(),
        "package_dirs": tuple(d.resolve() for d in args.package_dir) or None,
    }
    spec = dataclasses.replace(spec, **{key: value for key, value in named.items() if value is not None})
    report = robot_report(spec.load())
    if args.json:
        print(json_layout.dumps(report, indent=2))
        return EXIT_OK
    lines = [
        f"URDF: {report['urdf']}",
        f"SRDF: {report['srdf'] or 'none'}"
        + (
            f" (it names links the URDF lacks: {', '.join(report['srdf_unknown_links'])}; their "
            "disable_collisions entries are skipped, as MoveIt skips them)"
            if report["srdf_unknown_links"]
            else ""
        ),
        f"limits: {report['limits_file'] or 'the documented defaults'}"
        + (f" (defaults for {', '.join(report['limits_defaulted'])})" if report["limits_defaulted"] else ""),
        f"planned joints ({len(report['joints'])}), range, velocity, acceleration, jerk limits:",
        *(
            f"  {j['name']}: [{j['lower']:.4g}, {j['upper']:.4g}] {j['unit']}, {j['velocity']:.4g}, "
            f"{j['acceleration']:.4g}, {j['jerk']:.4g}"
            + (
                f" (the URDF's range [{j['urdf_range'][0]:.4g}, {j['urdf_range'][1]:.4g}] {j['unit']}, "
                "planned within one turn either way)"
                if j["urdf_range"]
                else ""
            )
            for j in report["joints"]
        ),
        f"held joints: {report['held'] or 'none'}",
        *(
            [
                f"base joints held at their identity pose (the scene's frame is their child link's): "
                f"{', '.join(report['base_joints'])}"
            ]
            if report["base_joints"]
            else []
        ),
        f"tool frame: {report['tcp_frame']}",
        f"collision shapes ({len(report['shapes'])}), each shape's largest distance beyond its link mesh "
        f"(sampled on {report['excess_samples']:,} points; about the spacing below the true largest):",
        *(_shape_line(shape) for shape in report["shapes"]),
        f"self pairs checked: {report['self_pairs_checked']}; touching by design (not checked): "
        f"{len(report['touching_by_design'])}; close by design (held to contact below their gap): "
        f"{len(report['close_by_design'])}",
    ]
    print(escaped("\n".join(lines)))
    return EXIT_OK


def _shape_line(shape: dict[str, Any]) -> str:
    """One collision shape's line: geometry, link, kind, excess."""
    if shape["kind"] == "exact mesh":
        bound = shape["bound_excess_m"]
        excess = "exact, its " + (
            "bounding capsule a bound" if bound is None else f"hull ({bound * 1000:.1f} mm beyond it) a bound"
        )
    elif shape["kind"] == "convex hull":
        excess = f"excess {shape['excess_m'] * 1000:.1f} mm (spacing {shape['spacing_m'] * 1000:.1f} mm)"
    else:
        excess = "exact"
    return f"  {shape['geometry']} ({shape['link']}): {shape['kind']}, {excess}"
