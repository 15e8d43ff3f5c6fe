"""``cpr-plan``: plan, check, show and batch-plan trajectories from the command line.

Exit codes (one mapping, :mod:`planning.outcome`): 0 success; 2 invalid input (missing file,
broken YAML, schema error, start or goal unreachable or inside the margin, bad parameters,
unwritable output); 3 no collision-free trajectory found (``plan``, ``paper``) or a
trajectory that fails the scene (``check``); 4 a bug; 130 interrupted (``Ctrl-C``,
``SIGTERM``). Errors are one line on stderr, never a traceback; on failure nothing is written.

Each command imports what it needs when it runs: ``cpr-plan batch``'s parent process only
dispatches scenes to workers and so starts without the planner, coal or numba.
"""

from planning.cli.app import console_main, main

__all__ = ["console_main", "main"]
