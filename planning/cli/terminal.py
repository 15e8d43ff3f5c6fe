"""Progress bars on a terminal (tqdm), imported when a command draws one."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planning.search.firefly import FireflyProgress


def terminal_bar(total: int, desc: str, unit: str, leave: bool = True) -> Any:
    """A tqdm bar sized to the terminal.

    A terminal that reports a size of 0 (a bare pty) would make tqdm draw nothing.
    """
    from tqdm import tqdm

    size = shutil.get_terminal_size((80, 24))
    return tqdm(total=total, desc=desc, unit=unit, leave=leave, ncols=size.columns, nrows=size.lines)


def firefly_progress(enabled: bool) -> tuple[Callable[[FireflyProgress], None] | None, Callable[[], None]]:
    """A tqdm bar over the search's firefly iterations when enabled (stdout is a terminal), and its closer.

    A search that refines a feasible seed without the firefly shows the seeds' best only.
    """
    if not enabled:
        return None, lambda: None
    bar: Any = None

    def update(progress: FireflyProgress) -> None:
        nonlocal bar
        if bar is None:
            bar = terminal_bar(progress.iterations, "search", "it", leave=False)
        else:
            bar.update(1)
        bar.set_postfix(best=f"{progress.best:.4g}")

    def close() -> None:  # idempotent: a command may close it early, and again on the way out
        nonlocal bar
        if bar is not None:
            bar.close()
            bar = None

    return update, close
