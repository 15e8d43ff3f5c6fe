"""The installed command's process: the collector off while it runs, and an exit that keeps every byte."""

from __future__ import annotations

import builtins
import dataclasses
import gc
import os
import subprocess
import sys
from pathlib import Path

import pytest

from planning.cli import process
from planning.cli.dataclass_code import KeptCode
from planning.pipeline.blas_threads import OPENBLAS_THREADS

ROOT = Path(__file__).resolve().parents[1]
BUFFERED = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
"""The environment, Python's output buffered (as a user's is), whatever this one says."""


def python(*arguments: str, env: dict[str, str] = BUFFERED) -> subprocess.CompletedProcess[str]:
    """``python ARGUMENTS`` in a new process, what it printed and its exit code."""
    command = [sys.executable, *arguments]
    return subprocess.run(command, capture_output=True, text=True, check=False, timeout=60, cwd=ROOT, env=env)


def reader_leaves(*arguments: str, env: dict[str, str] = BUFFERED) -> tuple[int, bytes]:
    """``python ARGUMENTS`` in a new process whose output's reader leaves at once: its exit code and stderr.

    As ``cpr-plan ... | head -0`` would: standard output is a pipe closed at its other end.
    """
    child = subprocess.Popen(
        [sys.executable, *arguments], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT, env=env
    )
    assert child.stdout is not None and child.stderr is not None
    child.stdout.close()
    code = child.wait(timeout=300)
    said = child.stderr.read()
    child.stderr.close()
    return code, said


def test_start_switches_the_collector_off_and_keeps_a_users_plugin_setting(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(gc, "disable", lambda: calls.append("disable"))
    monkeypatch.setenv(process.PYDANTIC_PLUGINS, "")  # the user's: every plugin loads
    monkeypatch.setattr(dataclasses, "exec", builtins.exec, raising=False)  # Python's own again after
    calls: list[str] = []
    process.start_process()
    assert calls == ["disable"]
    assert os.environ[process.PYDANTIC_PLUGINS] == ""
    assert isinstance(dataclasses.exec, KeptCode)  # type: ignore[attr-defined]


def test_end_process_exits_with_the_code_and_every_byte_written() -> None:
    written = "x" * 100_000  # more than a pipe's buffer, part of it still in Python's at the end
    completed = python(
        "-c",
        "import sys, logging\n"
        "from planning.cli.process import end_process\n"
        "logging.basicConfig(stream=sys.stderr)\n"
        f"sys.stdout.write({written!r}); logging.getLogger('t').warning('said')\n"
        "sys.stderr.write('last')\n"
        "end_process(3)\n",
    )
    assert completed.returncode == 3
    assert completed.stdout == written
    assert completed.stderr == "WARNING:t:said\nlast"


def test_end_process_waits_for_a_thread_that_still_runs() -> None:
    completed = python(
        "-c",
        "import threading, time\n"
        "from planning.cli.process import end_process\n"
        "threading.Thread(target=lambda: (time.sleep(0.3), print('thread done'))).start()\n"
        "end_process(5)\n",
    )
    assert completed.returncode == 5 and completed.stdout == "thread done\n"


def test_end_process_says_nothing_when_the_reader_went_away() -> None:
    code = (
        "import time\nfrom planning.cli.process import end_process\ntime.sleep(0.5)\nprint(1)\nend_process(0)"
    )
    assert reader_leaves("-c", code) == (0, b"")


def test_the_installed_command_runs_with_the_collector_off(tmp_path: Path) -> None:
    script = tmp_path / "probe.py"
    script.write_text(
        "import gc\n"
        "from planning.cli import app\n"
        "app.main = lambda restore_signals: print('collector', gc.isenabled()) or 7\n"
        "app.console_main()\n"
    )
    completed = python(str(script))
    assert completed.returncode == 7 and completed.stdout == "collector False\n"
    assert completed.stderr == ""


def test_the_installed_command_holds_blas_to_one_thread_and_searches_no_plugins(tmp_path: Path) -> None:
    script = tmp_path / "probe.py"
    script.write_text(
        "import sys\n"
        "from planning.cli import app\n"
        "print('numpy before', 'numpy' in sys.modules)\n"
        "def main(restore_signals):\n"
        "    import numpy, threadpoolctl\n"
        "    from planning.pipeline import blas_threads\n"
        "    pools = threadpoolctl.ThreadpoolController().select(user_api='blas').info()\n"
        "    blas_threads._controller = None  # not searched for: the process is on one thread\n"
        "    blas_threads.one_blas_thread(lambda: None)()\n"
        "    print('threads', sorted({pool['num_threads'] for pool in pools}))\n"
        "    import pydantic.plugin._loader as plugins\n"
        "    print('plugins', list(plugins.get_plugins()), plugins._plugins)\n"
        "    return 0\n"
        "app.main = main\n"
        "app.console_main()\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in (OPENBLAS_THREADS, process.PYDANTIC_PLUGINS)}
    completed = python(str(script), env=env)
    assert completed.stderr == ""
    assert completed.stdout == "numpy before False\nthreads [1]\nplugins [] None\n"  # none searched for


def test_a_library_caller_keeps_its_blas_threads() -> None:
    completed = python(
        "-c",
        "import numpy, os\n"
        "from planning.cli.process import start_process\n"
        "start_process()\n"
        f"print(os.environ.get({OPENBLAS_THREADS!r}))\n",
    )
    assert completed.returncode == 0 and completed.stdout == "None\n"


@pytest.mark.parametrize("unbuffered", [False, True], ids=["buffered", "PYTHONUNBUFFERED"])
def test_a_command_whose_reader_left_runs_to_its_end_and_says_nothing(
    tmp_path: Path, unbuffered: bool
) -> None:
    done = tmp_path / "done"
    code = (
        "import sys, time\n"
        "from planning.cli.process import end_process, start_process\n"
        "start_process()\n"
        "time.sleep(0.5)\n"
        "print('x' * 100_000)\n"  # more than the pipe holds: the write that finds the reader gone
        "print('after', file=sys.stdout, flush=True)\n"
        f"open({str(done)!r}, 'w').write('files written')\n"
        "end_process(4)\n"
    )
    env = {**BUFFERED, "PYTHONUNBUFFERED": "1"} if unbuffered else BUFFERED
    assert reader_leaves("-c", code, env=env) == (4, b"")
    assert done.read_text() == "files written"


@pytest.mark.slow
def test_a_plan_piped_to_a_reader_that_leaves_writes_its_files_and_exits_zero(tmp_path: Path) -> None:
    plan = ("-m", "planning.cli", "plan", "examples/scenes/shelf.yaml", "--out", str(tmp_path))
    assert reader_leaves(*plan, env={**BUFFERED, "PYTHONUNBUFFERED": "1"}) == (0, b"")
    assert (tmp_path / "trajectory.json").is_file() and (tmp_path / "manifest.json").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["shelf.yaml", "panda_pick_and_place.yaml"])
def test_a_plan_and_a_task_written_call_neither_numpys_unique_nor_median(scene: str, tmp_path: Path) -> None:
    # both import numpy.ma at their first call (9 ms of a new process), which nothing here needs
    # (cpr_kin.common.arrays); numba's just-in-time dispatch imports it too, so the calls are counted
    completed = python(
        "-c",
        "import numpy as np\n"
        "called = []\n"
        "for name in ('unique', 'median'):\n"
        "    def spy(*args, _real=getattr(np, name), _name=name, **kwargs):\n"
        "        called.append(_name)\n"
        "        return _real(*args, **kwargs)\n"
        "    setattr(np, name, spy)\n"
        "from planning.cli.app import main\n"
        f"code = main(['plan', 'examples/scenes/{scene}', '--out', {str(tmp_path)!r}])\n"
        "print(code, sorted(set(called)))\n",
    )
    assert completed.returncode == 0, completed.stderr[-2000:]
    assert completed.stdout.splitlines()[-1] == "0 []"
