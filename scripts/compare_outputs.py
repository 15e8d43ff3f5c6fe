"""Compare the files two checkouts write for the bundled scenes, byte for byte.

Runs ``cpr-plan plan`` on every bundled scene (``planning/scenes/*.yaml``) for seeds
``0 .. --seeds - 1`` and ``cpr-plan paper`` once, in new processes, first with this
checkout's code and then with ``--compare DIR`` (another checkout, e.g. ``git worktree add
/tmp/base <commit>``), and compares every file written (``trajectory.json``,
``samples.csv``, ``report.md``). The one expected difference, the checkout's own folder in
the recorded URDF path, is replaced by ``<checkout>``, and the wall times in ``report.md``'s
time rows are masked, before comparing (``trajectory.json`` records no wall time). JSON files
are compared as documents, value for value (floats exactly), not by their layout, which
changed when ``planning.io.json_layout`` came.
``manifest.json`` is left out: it lists the other files' hashes, and older checkouts do not
write it.

A refactoring must print ``identical`` for every file; a change that means to alter results
(a new timing, say) shows here which files and scenes it alters. Exit code 0 when all are
identical, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from planning.cli.arguments import COUNT

COMMAND = "import sys; from planning.cli import main; sys.exit(main())"
WALL_TIME = re.compile(rb"\d+\.\d+ s\b")


def normalised(content: bytes, checkout: Path, name: str) -> bytes:
    """``content`` with the checkout's folder and, in ``report.md``'s time rows, wall times masked.

    A JSON file becomes its document written compactly, so that layouts compare alike.
    """
    content = content.replace(str(checkout).encode(), b"<checkout>")
    if name.endswith(".json"):
        return json.dumps(json.loads(content)).encode()
    if name != "report.md":
        return content
    lines = content.split(b"\n")
    return b"\n".join(WALL_TIME.sub(b"<wall time> s", line) if b" time" in line else line for line in lines)


def run(code: Path, arguments: list[str], cwd: Path) -> int:
    """``cpr-plan ARGUMENTS`` with ``code`` first on the path; its exit code."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    done = subprocess.run(
        [sys.executable, "-c", COMMAND, *arguments], env=env, cwd=cwd, capture_output=True, text=True
    )
    if done.returncode not in (0, 3):
        raise SystemExit(f"{code}: cpr-plan {' '.join(arguments)} failed ({done.returncode}):\n{done.stderr}")
    return done.returncode


def outputs(code: Path, scenes: list[Path], seeds: int, work: Path) -> dict[str, bytes]:
    """Every file the runs write, by ``<run>/<file>``, with the checkout's folder normalised."""
    files: dict[str, bytes] = {}
    work.mkdir(parents=True)
    runs: dict[str, list[str]] = {"paper": ["paper"]}
    for scene in scenes:
        for seed in range(seeds):
            runs[f"{scene.stem}-seed{seed}"] = ["plan", str(scene), "--seed", str(seed)]
    for label, arguments in runs.items():
        out = work / label
        code_returned = run(code, [*arguments, "--out", str(out)], work)
        files[f"{label}/exit"] = str(code_returned).encode()
        for path in sorted(out.glob("*")) if out.is_dir() else []:
            if path.suffix in (".json", ".csv", ".md") and path.name != "manifest.json":
                files[f"{label}/{path.name}"] = normalised(path.read_bytes(), code.resolve(), path.name)
    return files


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", type=Path, required=True, help="the other checkout")
    parser.add_argument("--seeds", type=COUNT, default=3, help="seeds per bundled scene (default: 3)")
    args = parser.parse_args()
    here = Path(__file__).resolve().parents[1]
    if not (args.compare / "planning").is_dir():
        raise SystemExit(f"--compare {args.compare}: not a checkout of this project (no planning/)")
    with tempfile.TemporaryDirectory() as tmp:
        scenes_dir = Path(tmp) / "scenes"  # the same scene paths (and names) for both
        scenes_dir.mkdir()
        bundled = sorted((here / "planning" / "scenes").glob("*.yaml"))
        scenes = [scenes_dir / p.name for p in bundled]
        for source, target in zip(bundled, scenes, strict=True):
            target.write_bytes(source.read_bytes())
        mine = outputs(here, scenes, args.seeds, Path(tmp) / "this")
        theirs = outputs(args.compare.resolve(), scenes, args.seeds, Path(tmp) / "other")
    differing = 0
    for name in sorted(set(mine) | set(theirs)):
        same = mine.get(name) == theirs.get(name)
        differing += not same
        missing = mine.get(name) is None or theirs.get(name) is None
        state = "identical" if same else ("missing on one side" if missing else "DIFFERS")
        print(f"{name:40s} {state}")
    print(f"\n{len(mine)} files here, {len(theirs)} there; {differing} differ")
    return 0 if differing == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
