"""Reports of a plan: ``report.md``, the CLI's summary, and the paper's figures beside ours.

Every figure comes from the plan's one record (:func:`plan_record`, whose metrics are
:meth:`planning.pipeline.metrics.Metrics.to_record`): the trajectory file, the batch summary and the
reports cannot disagree.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # types only: a batch's parent formats tables without the planner
    from planning.pipeline.result import PlanResult


def paper_figures() -> dict[str, Any]:
    """The paper's reported figures (docs/paper_case.md), data of its case beside its scene.

    ``planning/scenes/paper_figures.json``: its FMA time [s], objective [s], node deviation
    and its limit [um], and each joint's jerk range by joint name.
    """
    figures: dict[str, Any] = json.loads(
        (resources.files("planning") / "scenes" / "paper_figures.json").read_text()
    )
    return figures


def plan_record(result: PlanResult, timings: bool = True) -> dict[str, Any]:
    """The trajectory file's ``metrics`` section: the metrics' record, the seed and the fitness kind."""
    settings = result.scene.planner
    return {**result.metrics.to_record(timings), "seed": settings.seed, "fitness_kind": settings.fitness}


def summary(result: PlanResult) -> dict[str, Any]:
    """The CLI's JSON summary of a plan: the scene, its margin and the record, wall times included."""
    return {
        "status": "ok",
        "scene": result.scene.name,
        "safety_margin": result.scene.safety_margin,
        **plan_record(result),
    }


def clearance_text(clearance_m: float) -> str:
    """A certified clearance [m] as the summaries and reports word it: ``unbounded`` with no obstacle.

    A scene without obstacles (or a segment away from all) has an infinite clearance, which
    the files write as ``null`` (:mod:`planning.io.json_layout`); a person reads why.
    """
    return f"{clearance_m:.4f} m" if np.isfinite(clearance_m) else "unbounded, no obstacle"


def summary_line(result: PlanResult) -> str:
    """The CLI's one-line summary of a plan."""
    r = plan_record(result)
    return (
        f"{result.scene.name}: verified trajectory of {r['duration']:.3f} s, certified clearance "
        f"{clearance_text(r['min_clearance'])} (margin {result.scene.safety_margin} m), "
        f"node deviation {r['max_node_deviation']:.3g}, "
        f"planned in {r['planning_time_s']:.3f} s ({r['evaluations']} evaluations)"
    )


def paper_rows(result: PlanResult) -> list[tuple[str, str, str]]:
    """``(figure, paper, ours)`` rows for the paper case."""
    r, paper = plan_record(result), paper_figures()
    firefly = result.scene.planner.firefly
    rows = [
        (
            f"FMA processing time (n={firefly.fireflies}, {firefly.iterations} iterations)",
            f"{paper['fma_time_s']:.0f} s",
            f"{r['optimiser_time_s']:.3f} s",
        ),
        ("planning time, end to end", "-", f"{r['planning_time_s']:.3f} s"),
        ("objective evaluations", "-", f"{r['evaluations']}"),
        ("objective value: PTP time t_sol", f"{paper['objective_s']} s", f"{r['t_sol']:.3f} s"),
        ("fitness (eq. 4)", "-", f"{r['fitness']:.4f}"),
        (
            "max node deviation (p=1e6, h=1 s)",
            f"{paper['node_deviation_um']} um (limit {paper['node_deviation_limit_um']:g} um)",
            f"{r['max_node_deviation'] * 1e6:.2f} um",
        ),
    ]
    for joint, (low, high) in paper["jerk"].items():
        unit = f"{result.robot.joint_unit(joint)}/s^3"
        rows.append(
            (
                f"jerk {joint} min / max",
                f"{low} / {high} {unit}",
                f"{r['jerk_min'][joint]:.4f} / {r['jerk_max'][joint]:.4f} {unit}",
            )
        )
    rows += [
        (
            "min clearance (certified)",
            f">= {result.scene.safety_margin} m (margin)",
            f"{r['min_clearance']:.4f} m",
        ),
        ("duration", "4 s", f"{r['duration']:.3f} s"),
        (
            "peak velocity, acceleration, jerk / limit",
            "-",
            ", ".join(f"{v:.2f}" for v in r["limit_utilisation"].values()),
        ),
    ]
    return rows


def report_markdown(result: PlanResult, paper: bool = False) -> str:
    """``report.md``: the figures of the plan, its jerk extrema and waypoints (and the paper's)."""
    r = plan_record(result)
    scene = result.scene
    rows = [
        ("duration", f"{r['duration']:.3f} s"),
        ("certified min clearance", f"{clearance_text(r['min_clearance'])} (margin {scene.safety_margin} m)"),
        ("PTP time t_sol (objective)", f"{r['t_sol']:.3f} s"),
        ("fitness", f"{r['fitness']:.4f}"),
        ("max node deviation", f"{r['max_node_deviation']:.3g}"),
        (
            "peak velocity, acceleration, jerk / limit",
            ", ".join(f"{v:.2f}" for v in r["limit_utilisation"].values()),
        ),
        ("evaluations", str(r["evaluations"])),
        ("planning time", f"{r['planning_time_s']:.3f} s"),
    ]
    lines = [
        f"# Plan: {scene.name}",
        "",
        f"Seed {r['seed']}, fitness `{r['fitness_kind']}`, "
        f"{len(scene.obstacles)} obstacle(s). Files: `trajectory.json` (cpr-trajectory/1), "
        "`samples.csv` (every IPO period).",
        "",
        "| figure | value |",
        "|---|---|",
        *[f"| {a} | {b} |" for a, b in rows],
        "",
        "| joint | jerk min | jerk max |",
        "|---|---|---|",
        *[f"| {n} | {r['jerk_min'][n]:.4g} | {r['jerk_max'][n]:.4g} |" for n in result.joint_names],
        "",
        *limits_section(result),
        *usage_section(result),
        "Waypoints (start, intermediate, goal):",
        "",
        *[f"- {np.round(w, 5).tolist()}" for w in result.waypoints],
        "",
    ]
    if paper:
        lines += ["## Beside the paper", "", markdown_table(paper_rows(result)), ""]
    return "\n".join(lines)


def limits_section(result: PlanResult) -> list[str]:
    """``report.md``'s lines on limits that are defaults, joints held and SRDF entries skipped; or none."""
    from cpr_kin.model.limits import DEFAULT_ACCELERATION_PER_S, DEFAULT_JERK_PER_S

    robot, lines = result.robot, []
    if robot.limits_defaulted:
        source = f"`{robot.limits_path}`" if robot.limits_path is not None else "no limits file"
        lines += [
            f"Acceleration and jerk limits of {', '.join(robot.limits_defaulted)} are the defaults "
            f"(a = {DEFAULT_ACCELERATION_PER_S:g} v per s, j = {DEFAULT_JERK_PER_S:g} a per s; {source}): "
            "give the maker's in a limits file for a faster motion.",
            "",
        ]
    if robot.ranges_narrowed:
        narrowed = ", ".join(
            f"{name} [{lower:.4g}, {upper:.4g}] rad" for name, (lower, upper) in robot.ranges_narrowed.items()
        )
        lines += [
            f"The URDF's ranges of {narrowed} pass one turn either way: planned within [-2 pi, 2 pi] rad.",
            "",
        ]
    if robot.held:
        held = ", ".join(f"{name} = {value:g}" for name, value in robot.held.items())
        lines += [f"Held (not planned): {held}.", ""]
    if robot.srdf_unknown_links:
        lines += [
            f"The SRDF `{robot.srdf_path}` names links the URDF lacks "
            f"({', '.join(robot.srdf_unknown_links)}): their disable_collisions entries were skipped, "
            "as MoveIt skips them.",
            "",
        ]
    if robot.overlapping_links:
        pairs = ", ".join(f"{a} / {b}" for a, b in robot.overlapping_links)
        lines += [
            f"Link pairs whose shapes collide in every sampled configuration, touching by design and "
            f"not checked (MoveIt's setup assistant disables them as always in collision): {pairs}.",
            "",
        ]
    held_to_contact = [c for c in robot.close_pairs if c.held_to_contact(result.scene.self_margin)]
    if held_to_contact:
        pairs = ", ".join(
            f"{c.links[0]} / {c.links[1]} ({1000 * c.largest_m:.1f} mm)" for c in held_to_contact
        )
        lines += [
            "Link pairs within the self margin in every sampled configuration where they do not "
            f"touch, held to contact only (their largest sampled distance): {pairs}.",
            "",
        ]
    if robot.capsule_meshes:
        lines += [
            f"Collision meshes checked as their bounding capsule (coal cannot hold their convex hull, or "
            "they are flat): "
            f"{', '.join(robot.capsule_meshes)}.",
            "",
        ]
    return lines


def usage_section(result: PlanResult) -> list[str]:
    """``report.md``'s lines on how much of each limit (kinematic, torque) the motion uses, over time."""
    from planning.utilisation import NEAR_LIMIT, limit_usage

    names = result.joint_names
    usage = limit_usage(result.trajectory, result.problem.robot.limits, dynamics=result.problem.dynamics)
    orders = usage.orders
    near = usage.share_near_limit()
    peaks = usage.usage.max(axis=0)
    rows = [
        (f"{t0:.2f}-{t1:.2f}", *(f"{u:.2f}" for u in peak), f"{orders[order]} of {names[joint]}")
        for t0, t1, peak, order, joint in usage.phases()
    ]
    return [
        "## Limit usage over time",
        "",
        f"Largest {', '.join(orders)} over its limit: "
        f"{', '.join(f'{v:.2f}' for v in peaks)} at the peak, "
        f"{', '.join(f'{v:.2f}' for v in usage.mean())} averaged over time. "
        f"Some limit is used to {NEAR_LIMIT:.0%} or more during {near[-1]:.0%} of the motion "
        f"({', '.join(f'{order} {share:.0%}' for order, share in zip(orders, near[:-1], strict=True))}). "
        "`samples.csv` has the kinematic usage at every IPO sample; `--plots` draws `utilisation.png`.",
        "",
        markdown_table(rows, ("time [s]", *orders, "nearest its limit")),
        "",
        *torque_lines(result),
    ]


def torque_lines(result: PlanResult) -> list[str]:
    """``report.md``'s lines on the joint torques: payload, effort limits, peak usage per joint."""
    dynamics = result.problem.dynamics
    utilisation = result.metrics.torque_utilisation
    if not utilisation:
        return ["No joint has a known effort limit in the URDF: the torques are not limited.", ""]
    payload = dynamics.payload
    carried = (
        "no payload"
        if payload is None
        else f"a {payload.mass_kg:g} kg payload at {list(payload.com_in_frame_m)} m in "
        f"'{payload.frame_on(result.robot)}'"
    )
    peaks = ", ".join(f"{name} {value:.2f}" for name, value in utilisation.items())
    lines = [
        f"Joint torques (RNEA every millisecond, {carried}; effort limits x torque_scale "
        f"{dynamics.torque_scale:g}): peak |torque| / effort {peaks}.",
        "",
    ]
    if dynamics.massless_links:
        lines += [
            f"Links with a shape but no `<inertial>` in the URDF, taken massless: "
            f"{', '.join(dynamics.massless_links)}.",
            "",
        ]
    return lines


def text_table(rows: Sequence[Sequence[str]], headers: Sequence[str] = ("figure", "paper", "ours")) -> str:
    """A fixed-width table of any number of columns."""
    widths = [max(len(str(r[i])) for r in [headers, *rows]) for i in range(len(headers))]
    lines = ["  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)) for row in [headers, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(
    rows: Sequence[Sequence[str]], headers: Sequence[str] = ("figure", "paper", "ours")
) -> str:
    """A Markdown table of any number of columns."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)
