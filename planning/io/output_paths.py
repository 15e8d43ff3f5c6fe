"""An output is never one of the command's inputs: ``--out`` naming the file read is refused.

Compared as files, not as names: the same inode through a symbolic or a hard link counts.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from planning.io.publish import OutputError


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)  # the same inode: through a symbolic or a hard link too
    except OSError:  # one of them is not there: not the same file
        return False


def check_not_inputs(outputs: Iterable[Path], inputs: Mapping[str, Path | None]) -> None:
    """Refuse an output that is one of a command's inputs (the same file, also through a link).

    Args:
        outputs: the files the command would write.
        inputs: the files it reads, by what they are (``"trajectory file"``), or ``None``.

    Raises:
        OutputError: naming the output, the input it is and the fix.
    """
    for output in outputs:
        for what, given in inputs.items():
            if given is not None and _same_file(Path(output), Path(given)):
                raise OutputError(
                    f"output '{output}' is the {what} '{given}', an input of this command; "
                    "writing it would destroy the input: give another output file"
                )
