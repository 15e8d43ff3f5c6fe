"""Which installed releases differ from the constraints file, and (``--write``) a new one.

``make test-latest`` installs the newest releases the project's ranges admit into
``.venv-latest`` and runs this with its Python: it prints every distribution whose installed
version is not the one pinned in ``requirements/constraints.txt`` (moved, new, gone), so
that a test failing there points at a release. ``make lock`` runs it with ``--write`` after
the tests passed, pinning what was tested.
"""

from __future__ import annotations

import argparse
import re
from importlib import metadata
from pathlib import Path

PROJECT = "cpr-firefly"
HEADER = """\
# Exact versions that `make` installs (`pip install -c requirements/constraints.txt ...`), so
# that a fresh machine gets what the tests passed with. The ranges a library user needs are in
# pyproject.toml. `make test-latest` tries the newest releases and prints what moved;
# `make lock` rewrites this file from them once the tests pass.
"""


def normalised(name: str) -> str:
    """A distribution name as pip compares them (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def pinned(path: Path) -> dict[str, str]:
    """``{name: version}`` of the ``name==version`` lines of a constraints file."""
    found = {}
    for line in path.read_text().splitlines():
        line = line.split("#")[0].strip()
        if "==" in line:
            name, version = line.split("==", 1)
            found[normalised(name)] = version.strip()
    return found


def installed() -> dict[str, str]:
    """``{name: version}`` of the distributions of this environment, but the project and pip's own."""
    found = {normalised(d.metadata["Name"]): d.version for d in metadata.distributions()}
    for own in (PROJECT, "pip", "setuptools", "wheel"):
        found.pop(own, None)
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("constraints", type=Path, help="the constraints file")
    parser.add_argument("--write", action="store_true", help="rewrite it with the installed versions")
    args = parser.parse_args()
    old, new = pinned(args.constraints), installed()
    moved = [f"{n} {old[n]} -> {new[n]}" for n in sorted(old.keys() & new.keys()) if old[n] != new[n]]
    added = [f"{n} {new[n]} (new)" for n in sorted(new.keys() - old.keys())]
    gone = [f"{n} {old[n]} (no longer installed)" for n in sorted(old.keys() - new.keys())]
    changes = moved + added + gone
    print(f"{len(changes)} distribution(s) differ from {args.constraints}:" if changes else "nothing moved")
    for line in changes:
        print(f"  {line}")
    if args.write:
        lines = [f"{name}=={version}" for name, version in sorted(new.items())]
        args.constraints.write_text(HEADER + "\n".join(lines) + "\n")
        print(f"wrote {args.constraints} ({len(lines)} pins)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
