"""``SIGINT`` and ``SIGTERM`` wherever they strike: inside compiled code, after the swap, too late.

Each case runs ``cpr-plan`` in a process of its own, and sends the signal when the process
says (a file it writes) that it has reached the moment under test: no wall-clock window.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from planning.io.bundled import bundled_scene_paths
from planning.io.publish import complete_set

SHELF = next(p for p in bundled_scene_paths() if p.stem == "shelf")

STUCK_IN_COMPILED_TIMING = """
import sys
from pathlib import Path

import numpy as np

import planning.pipeline.timing as timing
from planning.cli.app import main
from planning.curves.moving_average import jerk_limited_motion

ready, scene, out = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
positions = np.cumsum(np.random.default_rng(0).uniform(0.0, 0.01, (4000, 5)), axis=0)
real = timing.time_path


def stuck(*args, **kwargs):  # the timing step, held inside a compiled kernel until signalled
    real(*args, **kwargs)
    ready.touch()
    while True:
        jerk_limited_motion(positions, 0.2, 0.01, np.full(5, 15.0), 3, 0.02, 0.125)


timing.time_path = stuck
sys.exit(main(["plan", scene, "--out", out], restore_signals=False))
"""

SIGNALLED_AFTER_THE_SWAP = """
import os
import shutil
import signal
import sys

from planning.cli.app import main

real = shutil.rmtree


def signalled(path, *args, **kwargs):  # the previous set's removal, right after the renames
    if ".old-" in str(path):
        os.kill(os.getpid(), int(sys.argv[3]))
    return real(path, *args, **kwargs)


shutil.rmtree = signalled
sys.exit(main(["plan", sys.argv[1], "--out", sys.argv[2], "--seed", "5"], restore_signals=False))
"""

SIGNALLED_TOO_LATE = """
import os
import signal
import sys

from planning.cli.app import main

code = main(["plan", sys.argv[1], "--out", sys.argv[2]], restore_signals=False)
os.kill(os.getpid(), signal.SIGINT)
os.kill(os.getpid(), signal.SIGTERM)
sys.exit(code)
"""


def python(script: str, *args: str) -> list[str]:
    return [sys.executable, "-c", script, *args]


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_inside_the_compiled_timing_code_is_an_interrupt(tmp_path: Path, signum: int) -> None:
    ready, out = tmp_path / "ready", tmp_path / "out"
    process = subprocess.Popen(
        python(STUCK_IN_COMPILED_TIMING, str(ready), str(SHELF), str(out)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not ready.exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert ready.exists(), "the plan never reached its timing step"
    process.send_signal(signum)  # most often inside a compiled call; at once after it otherwise
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr  # a SystemError wrapping the interrupt was exit 4
    assert stderr == "cpr-plan plan: interrupted; nothing written\n"
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_after_the_swap_says_the_new_set_is_complete(tmp_path: Path, signum: int) -> None:
    out = tmp_path / "out"
    first = subprocess.run([sys.executable, "-m", "planning.cli", "plan", str(SHELF), "--out", str(out)])
    assert first.returncode == 0  # a previous set, replaced by the next plan
    done = subprocess.run(
        python(SIGNALLED_AFTER_THE_SWAP, str(SHELF), str(out), str(int(signum))),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 130
    assert done.stderr == f"cpr-plan plan: interrupted; the new set in '{out}' is complete\n"
    assert complete_set(out) and json.loads((out / "trajectory.json").read_text())["metrics"]["seed"] == 5
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no .out.old-*, no .out.new-*


@pytest.mark.slow
def test_a_signal_once_the_command_is_over_changes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = subprocess.run(
        python(SIGNALLED_TOO_LATE, str(SHELF), str(out)), capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0 and done.stderr == "" and "Traceback" not in done.stdout
    assert complete_set(out)


def test_a_swallowed_signal_is_raised_again_at_the_checkpoint() -> None:
    # a compiled extension's import swallowed the interrupt once (the command then wrote its
    # files); the signal is recorded, and the checkpoint before publishing raises it again
    import os

    from planning.cli.signals import checkpoint, interrupts

    with interrupts() as signalled:
        checkpoint()  # nothing came: nothing raised
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1.0)  # the handler runs here
        except KeyboardInterrupt:
            pass  # swallowed, as the import did
        assert signalled()
        with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
            checkpoint()
    with interrupts():
        checkpoint()  # a new command starts with no signal
