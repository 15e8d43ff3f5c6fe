"""The scenes that ship with the package (``planning/scenes/*.yaml``), the paper case first.

The paper case (docs/paper_case.md) exists once, as ``planning/scenes/paper.yaml``:
:func:`paper_scene` loads it, ``cpr-plan paper`` plans it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

from planning.io.scene_file import load_scene
from planning.pipeline.scene import Scene


def bundled_scene_paths() -> list[Path]:
    """Every bundled scene file, sorted by name."""
    return sorted(paper_scene_path().parent.glob("*.yaml"))


def paper_scene_path() -> Path:
    """The bundled paper scene, ``planning/scenes/paper.yaml``."""
    return Path(str(resources.files("planning") / "scenes" / "paper.yaml"))


def paper_scene(seed: int = 0, **planner_changes: Any) -> Scene:
    """The paper case with the paper's parameters, and the planner changes given.

    Start TCP (0.5, 0.45, 0.25), goal (-0.5, 0.45, 0.25), a 0.3 m cube centred at
    (0, 0.6, 0.15), margin 0.1 m; n = 50, alpha = 1, beta0 = 0.5, 50 iterations, 3
    waypoints, node deviation at most 20 um; spline N = 4, h = 1 s (4 s), p = 1e6, jerk
    only, natural ends.

    Args:
        seed: seed of the search.
        planner_changes: other planner settings, by their scene-file keys
            (:meth:`~planning.pipeline.settings.PlannerSettings.updated`), e.g. ``fireflies=10``.
    """
    scene = load_scene(paper_scene_path())
    return scene.with_planner(seed=seed, **planner_changes)
