"""The process of the installed ``cpr-plan``: it runs one command, then it ends.

A long-lived Python process does five things that a process running one command need not;
each costs a new ``cpr-plan plan`` tens of milliseconds of its half second (docs/benchmarks.md,
the new-process row):

- **the cyclic garbage collector while the command runs.** Its collections walk every object
  the imports made (NumPy, Pinocchio, pydantic's schemas: some fifty thousand it tracks), again
  and again while they are made, to find the few cycles a command leaves: about two thousand
  objects in a plan, most of them the imports' own, no more in a task of two seconds than in a
  plan of a tenth (peak memory of the example scenes within 1 MB either way). :func:`start_process`
  switches it off; a library caller keeps it.
- **BLAS threads given back after each plan.** A plan holds BLAS to one thread
  (:mod:`planning.pipeline.blas_threads`); a process that runs one command holds it so from its
  start (:func:`start_process`), before NumPy loads OpenBLAS, and needs no search of its
  libraries for their thread pools.
- **pydantic's plugins.** Before its first validator, pydantic reads the entry points of every
  installed distribution for plugins (tools that watch a program's own models); the command's
  only models are its file schemas. :func:`start_process` sets ``PYDANTIC_DISABLE_PLUGINS`` to
  ``__all__`` unless the environment sets it (an empty value lets every plugin load).
- **compiling its dataclasses' methods.** Python compiles each dataclass's methods from text
  when the class is made, some fifty milliseconds of a plan's classes; the process reads the
  code compiled by an earlier one instead, and keeps what it compiled for the next
  (:mod:`planning.cli.dataclass_code`).
- **Python's teardown.** On exit Python takes apart every module and the robot's models one by
  one. :func:`end_process` flushes the output, keeps what the robot's near cells learned
  (:func:`cpr_kin.collision.learned_cells.keep_learned`, which Python's exit functions would
  run) and ends the process at once (as mypy does), unless a thread of the command still runs
  (then Python's own exit waits for it, as it would).

And one it needs that a library caller does not: its output's reader may leave
(``cpr-plan plan ... | head -1``). A write to that pipe then fails, mid-command, whenever
Python hands it on (at once with ``PYTHONUNBUFFERED`` set, else when its buffer fills or is
flushed); :func:`start_process` makes the command's standard output and error go quiet
instead (:class:`QuietWhenReaderLeaves`), so the command runs to its end, writes its files
and exits with its own code, whatever the buffering.
"""

from __future__ import annotations

import contextlib
import gc
import os
import sys
import threading
from typing import Any, NoReturn, TextIO, cast

from planning.pipeline.blas_threads import one_thread_for_process

PYDANTIC_PLUGINS = "PYDANTIC_DISABLE_PLUGINS"
"""pydantic's variable naming the plugins it leaves out (``__all__``: every one, no search)."""


def start_process() -> None:
    """Set up the process for one command (module docstring).

    No cyclic collector, one BLAS thread, no search for pydantic's plugins unless the
    environment names some, the dataclasses' methods compiled before reused.
    """
    gc.disable()
    one_thread_for_process()
    # imported here, not with this module: `python -m planning.cli.dataclass_code` runs it unimported
    from planning.cli.dataclass_code import reuse_dataclass_code

    reuse_dataclass_code()
    os.environ.setdefault(PYDANTIC_PLUGINS, "__all__")
    sys.stdout = cast(TextIO, QuietWhenReaderLeaves(sys.stdout))
    sys.stderr = cast(TextIO, QuietWhenReaderLeaves(sys.stderr))


class QuietWhenReaderLeaves:
    """A text stream that goes quiet once its reader has left (a pipe closed at its other end).

    Writes and flushes go to ``stream``; the first that finds the pipe broken points the
    stream's file at the null device, and everything after it, what was still buffered too,
    goes there. Every other attribute is ``stream``'s.
    """

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        """Write ``text``; nothing is said where the reader has left."""
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._leave()
            return len(text)

    def flush(self) -> None:
        """Flush the stream; nothing is said where the reader has left."""
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._leave()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)

    def _leave(self) -> None:
        """Point the stream's file at the null device: what it still holds, and all after, is dropped."""
        with contextlib.suppress(OSError, ValueError):  # a stream without a file of its own: nothing to point
            quiet = os.open(os.devnull, os.O_WRONLY)
            os.dup2(quiet, self._stream.fileno())
            os.close(quiet)


def end_process(code: int) -> NoReturn:
    """Exit with ``code``, the output flushed, without Python's teardown where no other thread runs."""
    logging = sys.modules.get("logging")  # its handlers flushed and closed, where anything logged
    if logging is not None:
        logging.shutdown()
    learned = sys.modules.get("cpr_kin.collision.learned_cells")  # what a robot's near cells learned
    if learned is not None:
        learned.keep_learned()
    methods = sys.modules.get("planning.cli.dataclass_code")  # the dataclasses' methods compiled
    if methods is not None:
        methods.keep_dataclass_code()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a reader gone, a stream closed: nothing to keep
            stream.flush()
    if threading.active_count() > 1:
        sys.exit(code)
    os._exit(code)
