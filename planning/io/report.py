"""Reports: the paper's figures beside ours, as text tables and Markdown."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from planning.planner import PlanResult

PAPER_FIGURES = {
    "fma_time_s": 53.0,
    "objective_s": 3.98,
    "node_deviation_um": 0.55,
    "node_deviation_limit_um": 20.0,
    "jerk": {"theta1": (-0.071, 0.2026), "d2": (-0.518, 0.673), "d3": (-0.292, 0.265)},
}
"""The paper's reported figures (DESIGN.md section 4)."""


def paper_rows(result: PlanResult) -> list[tuple[str, str, str]]:
    """``(figure, paper, ours)`` rows for the paper case."""
    m = result.metrics
    settings = result.scene.planner
    rows = [
        (
            f"FMA processing time (n={settings.fireflies}, {settings.iterations} iterations)",
            f"{PAPER_FIGURES['fma_time_s']:.0f} s",
            f"{m.optimiser_time_s:.3f} s",
        ),
        ("planning time, end to end", "-", f"{m.planning_time_s:.3f} s"),
        ("objective evaluations", "-", f"{m.evaluations}"),
        ("objective value: PTP time t_sol", f"{PAPER_FIGURES['objective_s']} s", f"{m.t_sol:.3f} s"),
        ("fitness (eq. 4)", "-", f"{m.fitness:.4f}"),
        (
            "max node deviation (p=1e6, h=1 s)",
            f"{PAPER_FIGURES['node_deviation_um']} um (limit 20 um)",
            f"{m.max_node_deviation * 1e6:.2f} um",
        ),
    ]
    for joint, (low, high) in PAPER_FIGURES["jerk"].items():  # type: ignore[attr-defined]
        unit = "rad/s^3" if joint.startswith("theta") else "m/s^3"
        rows.append(
            (
                f"jerk {joint} min / max",
                f"{low} / {high} {unit}",
                f"{m.jerk_min[joint]:.4f} / {m.jerk_max[joint]:.4f} {unit}",
            )
        )
    rows += [
        (
            "min clearance (certified)",
            f">= {result.scene.safety_margin} m (margin)",
            f"{m.min_clearance:.4f} m",
        ),
        ("duration", "4 s", f"{m.duration:.3f} s"),
        (
            "peak velocity, acceleration, jerk / limit",
            "-",
            ", ".join(f"{v:.2f}" for v in m.limit_utilisation.values()),
        ),
    ]
    return rows


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
