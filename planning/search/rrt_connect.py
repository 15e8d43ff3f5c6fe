"""RRT-Connect (Kuffner & LaValle 2000) with shortcutting: a fast first path to seed the search.

The firefly searches a few waypoints well but cannot find a narrow passage by chance: a way
under a beam or through a window is a small region of its space. A sampling planner finds one
in milliseconds, and its path, cut to a few waypoints, seeds the firefly's population
(:func:`planning.search.waypoints.waypoints_along`).

Two trees grow from start and goal: one extends a step towards a random sample, the other
then greedily connects to the new node; they swap roles every sample. The step is by default
a fifth of the sampling box's diagonal, OMPL's default range (``docs/tuning.md``). The
connection is checked once the extension is known, from where it stopped: checking both in
one call, the connection towards the step's end, saves a call when the extension reaches
it but wastes the connection's checks when it stops short, as most do on a 6- or 7-joint
arm (``docs/tuning.md``). Edges are checked in batches as :mod:`planning.search.edges`
describes (not certified: the executed spline gets the certified check). Distances are
robot motion bounds ``sum_j R_j |dq_j|`` [m] with the joints' motion radii
(:func:`cpr_kin.motion_radii`), so a step means the same in every joint whatever its unit.
The path found is then shortened (:func:`planning.search.edges.shortcut`); given the joints'
speeds and ``joint_shortcuts`` (none by default), also one joint at a time where that makes it
faster (a joint the trees moved at random, the slow one as far as the fast ones). All
randomness comes from the generator passed.

The trees may grow on coarser checks than the path must hold (``explore_resolution_m``, as
OMPL's motion checks are, a share of the space's extent): most edges a tree tries are
thrown away, and a dense check of each would dominate the planner's time on a 6- or 7-joint
arm. The shortened path's few edges are then checked at ``resolution_m``; an edge that
passes between two coarse checks through an obstacle is replaced by RRT-Connect's path
between its ends at that spacing, and when none is found the whole search runs again at it.
The path returned always holds at ``resolution_m``. Where the validity has a cheaper screen
(:class:`~planning.search.edges.ScreenedValidity`: the obstacles without the robot's own pairs),
the coarse draw grows the trees on it, and its path is held as above under the validity itself;
where a vertex of it fails that, the coarse draw is made again on the validity.

A share of the samples (``local_share``) is drawn about a random node of the tree they
extend (a normal spread of ``local_spread`` of each joint's range), the others uniformly in
the box. A tree rooted in a pocket (a goal between cans on a shelf) extended only towards
uniform samples hits the pocket's walls nearly every time, for thousands of samples, while
the other tree fills the free space; samples about its own nodes let it grow through the
pocket to its way out (``docs/tuning.md``).

A :class:`Relaxation` lets the trees go on under a looser validity after some samples (a
smaller clearance, where a passage is narrower than the one asked): what they grew holds
under it too, so no sample is drawn again; where start or goal fails the strict validity,
the looser one holds from the start. A path found under it is marked ``relaxed``.

A draw given :class:`~planning.search.rrt_trees.GrownTrees` goes on growing the trees an
earlier draw between the same ends left there when it found no path (the hulls' draw, for
the meshes'; under its relaxation at once where they grew under the earlier one's), and
leaves its own there when it finds none (not where its ends asked for the relaxation).
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planning.errors import PlanningError
from planning.search.edges import Edges, Validity, screen_of, shortcut
from planning.search.rrt_settings import RANGE_FRACTION, RrtSettings
from planning.search.rrt_trees import GrownTrees, Sampler, Tree, connect

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RrtPath:
    """A path found by :func:`rrt_connect`.

    Attributes:
        path: ``(k, d)`` vertices from start to goal, shortened [joint units].
        samples: random samples drawn.
        checks: configurations checked.
        relaxed: found under the :class:`Relaxation`'s validity (it holds under that one only).
    """

    path: FloatArray
    samples: int
    checks: int
    relaxed: bool = False


@dataclass(frozen=True)
class Relaxation:
    """A looser validity the trees go on with after ``after_samples`` samples (module docstring).

    Attributes:
        valid: the looser check: it accepts every configuration the strict one accepts.
        after_samples: samples drawn under the strict validity first.
    """

    valid: Validity
    after_samples: int


def rrt_connect(
    valid: Validity,
    start: FloatArray,
    goal: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    weights: FloatArray,
    rng: np.random.Generator,
    settings: RrtSettings | None = None,
    stop: Callable[[], bool] | None = None,
    relaxation: Relaxation | None = None,
    grown: GrownTrees | None = None,
    *,
    speeds: FloatArray | None = None,
) -> RrtPath | None:
    """A valid path from ``start`` to ``goal`` in the box ``[lower, upper]``, or ``None``.

    ``None`` at once when ``start`` or ``goal`` is not valid itself (nor under the
    relaxation): no valid path begins or ends there, and the samples would be spent for
    nothing (a goal closer to an obstacle than the clearance asked, though outside the margin).

    Args:
        valid: the batched validity check.
        start: ``(d,)`` start configuration [joint units].
        goal: ``(d,)`` goal configuration.
        lower: ``(d,)`` lower bounds of the samples.
        upper: ``(d,)`` upper bounds.
        weights: ``(d,)`` motion radius of each joint [m per joint unit], > 0.
        rng: the source of every random draw.
        settings: the planner's parameters (default :class:`RrtSettings`).
        stop: asked before every sample; ``True`` ends the search without a path (a time
            limit). ``None``: never.
        relaxation: the looser validity the trees go on with after its samples (``None``:
            none; module docstring).
        grown: the trees an earlier draw between the same ends left, under a validity
            ``valid`` accepts too, to go on growing; and where this draw leaves its own when it
            finds no path (:class:`~planning.search.rrt_trees.GrownTrees`). ``None``: new trees.
        speeds: ``(d,)`` the joints' velocity limits [joint units/s], > 0: the found path's
            joints are then straightened one at a time where that makes it faster
            (``settings.joint_shortcuts`` attempts). ``None``: not.
    """
    settings = settings or RrtSettings()
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    weights = np.asarray(weights, dtype=float)
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if not (weights.shape == start.shape == goal.shape and np.all(weights > 0)):
        raise PlanningError(f"weights {weights.tolist()} must be positive, one per joint of start and goal")
    if speeds is not None:
        speeds = np.asarray(speeds, dtype=float)
        if not (speeds.shape == start.shape and np.all(speeds > 0) and np.all(np.isfinite(speeds))):
            raise PlanningError(f"speeds {speeds.tolist()} must be positive and finite, one per joint")
    relaxed = False
    if not np.all(valid(np.stack([start, goal]))):
        if relaxation is None or not np.all(relaxation.valid(np.stack([start, goal]))):
            return None
        valid, relaxation, relaxed = relaxation.valid, None, True  # the ends ask for it
    explore_m = settings.explore_resolution_m or settings.resolution_m
    step_m = settings.step_m
    if step_m is None:
        diagonal = float(np.linalg.norm(weights * (np.asarray(upper) - np.asarray(lower))))
        step_m = max(explore_m, RANGE_FRACTION * diagonal)
    if explore_m > settings.resolution_m:
        keeping = None if relaxed else grown  # the ends' relaxation is not the coarse draw's to tell
        box = (lower, upper)
        found = _lazy(
            valid, start, goal, box, weights, rng, settings, step_m, stop, relaxation, keeping, speeds=speeds
        )
        return found if found is None or not relaxed else dataclasses.replace(found, relaxed=True)
    kept = None if grown is None else grown.take(start, goal, settings.resolution_m, relaxation is not None)
    if kept is not None and grown is not None and grown.relaxed and relaxation is not None:
        valid, relaxation, relaxed = relaxation.valid, None, True  # the trees hold under it only
    edges = Edges(valid, weights, settings.resolution_m)
    if edges.free_fraction(start, goal) == 1.0:
        return RrtPath(np.array([start, goal]), 0, edges.checks, relaxed)
    trees, strict_checks = kept or (Tree(start), Tree(goal)), 0
    draw = Sampler(lower, upper, settings)
    for sample in range(1, settings.max_samples + 1):
        if stop is not None and stop():
            break
        if relaxation is not None and sample > relaxation.after_samples:  # the trees hold under it
            strict_checks, edges = edges.checks, Edges(relaxation.valid, weights, settings.resolution_m)
            relaxation, relaxed = None, True
        grow, other = trees[(sample - 1) % 2], trees[sample % 2]
        target = draw(grow, rng)
        near = grow.nearest(target, weights)
        origin = grow.nodes[near]
        length = float(np.abs(target - origin) @ weights)
        if length <= 1e-12:
            continue
        end = origin + (target - origin) * min(1.0, step_m / length)
        extended = edges.free_fraction(origin, end)
        if extended == 0.0:
            continue
        new = grow.add(origin + extended * (end - origin), near)
        other_near = other.nearest(grow.nodes[new], weights)
        connected = edges.free_fraction(other.nodes[other_near], grow.nodes[new])
        joined = connect(other, other_near, grow.nodes[new], connected, step_m, weights)
        if joined is not None:
            # root of grow ... new == joined ... root of other (the meeting point once)
            path = np.concatenate([grow.branch(new)[::-1], other.branch(joined)[1:]])
            if grow is not trees[0]:
                path = path[::-1]
            path = shortcut(
                path, edges, rng, settings.shortcuts, joint_attempts=settings.joint_shortcuts, speeds=speeds
            )
            return RrtPath(path, sample, strict_checks + edges.checks, relaxed)
    if grown is not None:  # no path: the trees, for the next draw
        grown.keep(trees, start, goal, settings.resolution_m, relaxed)
    return None


def _lazy(
    valid: Validity,
    start: FloatArray,
    goal: FloatArray,
    box: tuple[FloatArray, FloatArray],
    weights: FloatArray,
    rng: np.random.Generator,
    settings: RrtSettings,
    step_m: float,
    stop: Callable[[], bool] | None,
    relaxation: Relaxation | None,
    grown: GrownTrees | None,
    *,
    speeds: FloatArray | None,
) -> RrtPath | None:
    """RRT-Connect on coarse edge checks, its path then held at ``resolution_m`` (module docstring).

    Where ``valid`` and the relaxation's validity have screens, the coarse draw grows the trees
    on them; where its path does not hold under the validities (a vertex fails, or an edge finds
    no detour), the coarse draw is made again on them, without the screens' trees. ``grown``
    serves the coarse draw: its trees are the ones a later draw can go on with.
    """
    fine = dataclasses.replace(settings, explore_resolution_m=None, step_m=step_m)
    coarse = dataclasses.replace(fine, resolution_m=settings.explore_resolution_m or settings.resolution_m)
    unshortened = dataclasses.replace(fine, shortcuts=0)
    spent = RrtPath(np.empty((0, len(start))), 0, 0)  # what a draw whose path did not hold took

    def held(found: RrtPath, search_again: bool) -> RrtPath | None:
        """``found`` held at ``resolution_m``: detours; where one fails, the fine draw or ``None``."""
        strict, loose = valid, relaxation
        if found.relaxed and relaxation is not None:  # the path holds at the looser validity only
            strict, loose = relaxation.valid, None
        edges = Edges(strict, weights, settings.resolution_m)
        if not search_again and not strict(found.path[1:]).all():
            return None  # a vertex the screen let through: no detour reaches it
        samples, checks = spent.samples + found.samples, spent.checks + found.checks
        pieces = [found.path[:1]]
        for a, b in itertools.pairwise(found.path):
            if edges.free_fraction(a, b) == 1.0:
                pieces.append(b[None])
                continue
            detour = rrt_connect(strict, a, b, *box, weights, rng, unshortened, stop)
            if detour is None:  # the coarse path is no guide here
                if not search_again:
                    return None
                again = rrt_connect(strict, start, goal, *box, weights, rng, fine, stop, loose, speeds=speeds)
                if again is None:
                    return None
                total = checks + edges.checks + again.checks
                return RrtPath(again.path, samples + again.samples, total, found.relaxed or again.relaxed)
            samples, checks = samples + detour.samples, checks + detour.checks
            pieces.append(detour.path[1:])
        path = np.concatenate(pieces)
        if len(path) > len(found.path):  # detours: shortened again, on the fine checks
            path = shortcut(
                path, edges, rng, settings.shortcuts, joint_attempts=settings.joint_shortcuts, speeds=speeds
            )
        return RrtPath(path, samples, checks + edges.checks, found.relaxed)

    screens = _screens(valid, relaxation)
    if screens is not None:
        screen, screen_relaxation = screens
        found = rrt_connect(
            screen, start, goal, *box, weights, rng, coarse, stop, screen_relaxation, grown, speeds=speeds
        )
        if found is None:
            return None
        kept = held(found, search_again=False)
        if kept is not None:
            return kept
        spent, grown = found, None  # the trees grew on the screens
    found = rrt_connect(
        valid, start, goal, *box, weights, rng, coarse, stop, relaxation, grown, speeds=speeds
    )
    return None if found is None else held(found, search_again=True)


def _screens(valid: Validity, relaxation: Relaxation | None) -> tuple[Validity, Relaxation | None] | None:
    """The screens of ``valid`` and of the relaxation's validity, where each has one, else ``None``."""
    screen = screen_of(valid)
    if screen is None:
        return None
    if relaxation is None:
        return screen, None
    relaxed_screen = screen_of(relaxation.valid)
    if relaxed_screen is None:
        return None
    return screen, Relaxation(relaxed_screen, relaxation.after_samples)
