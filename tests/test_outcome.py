from __future__ import annotations

import pickle
import signal

import numpy as np
import pytest

import cpr_kin as ck
from planning.errors import (
    CprPlanError,
    NoTrajectoryFoundError,
    PlanningError,
    SceneError,
    TaskSegmentError,
    ToolLineBrokenError,
)
from planning.outcome import STATUS_EXIT, Interrupted, classify, interruption


def no_trajectory() -> NoTrajectoryFoundError:
    check = ck.CurveCheck(
        accepted=False, margin_m=0.1, step_m=0.005, times=np.empty(0), clearance_m=np.empty((0, 2)),
        certified_min_m=-1.0, sampled_min_m=np.nan, worst_time=np.nan, worst_group="", worst_pair=None,
        violating_groups=ck.GROUPS,
    )  # fmt: skip
    return NoTrajectoryFoundError("no collision-free trajectory found", check)


def wrapped_interrupt() -> SystemError:
    try:
        try:
            raise KeyboardInterrupt(signal.Signals.SIGTERM.name)
        except KeyboardInterrupt as interrupt:
            raise SystemError("CPUDispatcher(...) returned a result with an exception set") from interrupt
    except SystemError as error:
        return error


@pytest.mark.parametrize(
    ("error", "status", "code"),
    [
        (SceneError("scene.yaml: safety_margin = -1"), "invalid", 2),
        (ck.UrdfError("URDF 'x.urdf' does not exist"), "invalid", 2),
        (PermissionError(13, "Permission denied", "/out/trajectory.json"), "invalid", 2),
        (no_trajectory(), "no_trajectory", 3),
        (IndexError("index 7 is out of bounds"), "error", 4),
        (KeyboardInterrupt("SIGINT"), "interrupted", 130),
        (wrapped_interrupt(), "interrupted", 130),
        (Interrupted("interrupted; the new set in 'out' is complete"), "interrupted", 130),
    ],
)
def test_every_failure_has_one_status_and_exit_code(error: BaseException, status: str, code: int) -> None:
    outcome = classify(error)
    assert (outcome.status, outcome.exit_code) == (status, code) == (status, STATUS_EXIT[status])
    assert "\n" not in outcome.message


def test_messages_name_the_file_and_escape_what_a_terminal_would_obey() -> None:
    assert classify(PermissionError(13, "Permission denied", "/out/x.json")).message == (
        "cannot use '/out/x.json': Permission denied"
    )
    assert classify(PlanningError("scene 'a\u202eb'")).message == "scene 'a\\u202eb'"
    assert classify(RuntimeError("boom")).message == "RuntimeError: boom"


def test_an_interrupt_is_found_through_the_chain_of_causes() -> None:
    assert isinstance(interruption(wrapped_interrupt()), KeyboardInterrupt)
    assert interruption(ValueError("no")) is None
    looped = ValueError("a")
    looped.__context__ = looped  # a cycle ends the walk
    assert interruption(looped) is None


@pytest.mark.parametrize(
    "error",
    [
        no_trajectory(),
        ToolLineBrokenError("joint 'd2' reaches its limit", 0.25),
        TaskSegmentError(3, "line", ToolLineBrokenError("a singularity", 0.5)),
        PlanningError("start q = [9] is outside its range"),
    ],
)
def test_an_error_from_a_worker_process_is_unpickled_whole(error: CprPlanError) -> None:
    # a process pool or Dask returns a worker's exception pickled; a constructor of other
    # arguments than the message once made unpickling raise TypeError in the caller
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is type(error) and str(again) == str(error)
    assert classify(again) == classify(error)
    for name, value in vars(error).items():
        assert repr(getattr(again, name)) == repr(value)
