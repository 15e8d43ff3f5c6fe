"""BLAS on one thread while a plan runs, the caller's setting given back after."""

from __future__ import annotations

from threadpoolctl import ThreadpoolController

from planning.io.bundled import paper_scene
from planning.pipeline.blas_threads import one_blas_thread
from planning.pipeline.planner import plan
from planning.pipeline.tuning import SearchTuning
from planning.search.firefly import FireflyProgress


def blas_threads() -> set[int]:
    return {pool["num_threads"] for pool in ThreadpoolController().select(user_api="blas").info()}


def test_a_plan_runs_blas_on_one_thread_and_restores_the_callers() -> None:
    with ThreadpoolController().limit(limits=2, user_api="blas"):
        before = blas_threads()
        seen: list[set[int]] = []

        def progress(_: FireflyProgress) -> None:  # called from inside the search
            seen.append(blas_threads())

        scene = paper_scene().with_planner(tuning=SearchTuning(explore_feasible_seed=True))
        plan(scene, progress=progress)  # the firefly explores first, reporting each iteration
        assert seen and all(threads == {1} for threads in seen)
        assert blas_threads() == before


def test_the_wrapped_function_keeps_its_name_and_result() -> None:
    @one_blas_thread
    def add(a: int, b: int = 1) -> int:
        """Sum."""
        return a + b

    assert add(2, b=3) == 5 and add.__name__ == "add" and add.__doc__ == "Sum."
