"""The robot package's notices: on a terminal's stderr, from the CLI and a batch's scene, not in a pipe."""

from __future__ import annotations

import io
import logging
import sys
from pathlib import Path
from typing import Any

import pytest

import planning.batch.items as items
from planning.notices import library_notices


class Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def test_library_notices_show_the_robot_packages_info_on_a_terminal_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    log = logging.getLogger("cpr_kin")
    before = (log.level, log.propagate, list(log.handlers))
    shown = Terminal()
    monkeypatch.setattr(sys, "stderr", shown)
    with library_notices("cpr-plan plan"):
        logging.getLogger("cpr_kin.compiled").info("compiling")
        logging.getLogger("cpr_kin.compiled").debug("not shown")
    logging.getLogger("cpr_kin.compiled").info("after: not shown")
    assert shown.getvalue() == "cpr-plan plan: compiling\n"
    assert (log.level, log.propagate, list(log.handlers)) == before
    piped = io.StringIO()
    monkeypatch.setattr(sys, "stderr", piped)
    with library_notices("cpr-plan plan"):
        logging.getLogger("cpr_kin.compiled").info("compiling")
    assert piped.getvalue() == ""


def test_a_batch_scene_shows_what_the_robot_package_says_on_its_workers_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a worker of a local batch writes to the terminal the batch runs in (loky's inherit it)
    scene = tmp_path / "scene.yaml"
    scene.write_text("start: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [-0.5, 0.45, 0.25]}\n")

    def planned(*_: Any) -> Any:
        logging.getLogger("cpr_kin.compiled").info("compiling")
        raise RuntimeError("stop here")  # the row says so; the notice was shown before

    monkeypatch.setattr(items, "_plan_outputs", planned)
    shown = Terminal()
    monkeypatch.setattr(sys, "stderr", shown)
    item = items.plan_scene_file(scene, tmp_path / "out")
    assert item.status == "error" and "stop here" in item.message
    assert shown.getvalue() == "cpr-plan batch: compiling\n"
