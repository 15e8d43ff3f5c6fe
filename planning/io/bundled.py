"""The scenes that ship with the package (``planning/scenes/*.yaml``), the paper case first.

The paper case (docs/paper_case.md) exists once, as ``planning/scenes/paper.yaml``:
:func:`paper_scene` loads it, ``cpr-plan paper`` plans it.
"""

from __future__ import annotations

import dataclasses
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


def duration_free_scenes() -> list[Scene]:
    """Every bundled scene with its duration free: the others as they are, the paper's freed.

    The paper case fixes its duration (4 s); freed, it is timed as fast as the limits allow
    like the others, as the benchmarks of durations over Ruckig's bound need (its name
    ``paper_free``).
    """
    scenes = [load_scene(path) for path in bundled_scene_paths() if path != paper_scene_path()]
    return [*scenes, dataclasses.replace(paper_scene(), name="paper_free", duration=None)]
