"""The documentation leads somewhere: its links, and the commands of the benchmarks' table.

A link names a file of the repository and, after ``#``, one of its headings as GitHub anchors
it: lower case, punctuation but ``-`` and ``_`` dropped, spaces as ``-``, a repeated heading
numbered ``-1``, ``-2``, ... Code (fenced blocks, inline spans) holds no links: an error
message quoted there (``Literal[int](1)``) is not one.

docs/benchmarks.md's Now table gives, for every figure, the command that prints it again: the
scripts, make targets and test files it names exist, and each option it gives a script is
one that script's ``--help`` lists.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = sorted([ROOT / "README.md", *(ROOT / "docs").glob("*.md")])
FENCED = re.compile(r"^```.*?^```", re.M | re.S)
INLINE_CODE = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6} (.+?)\s*#*$", re.M)
EXTERNAL = re.compile(r"^[a-z][a-z0-9+.-]*:", re.I)


def prose(text: str) -> str:
    """``text`` without its fenced code blocks."""
    return FENCED.sub("", text)


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading's text (before numbering repeats)."""
    text = re.sub(r"[^\w\- ]", "", heading.replace("`", "").strip().lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """Every anchor of the Markdown file ``path``'s headings, repeats numbered as GitHub does."""
    seen: dict[str, int] = {}
    found = set()
    for match in HEADING.finditer(prose(path.read_text())):
        base = anchor(match.group(1))
        count = seen.get(base, 0)
        found.add(base if count == 0 else f"{base}-{count}")
        seen[base] = count + 1
    return found


def broken_links(path: Path) -> list[str]:
    """The relative links of ``path`` whose file or heading does not exist."""
    broken = []
    for match in LINK.finditer(INLINE_CODE.sub("", prose(path.read_text()))):
        link = match.group(1)
        if EXTERNAL.match(link):
            continue
        name, _, fragment = link.partition("#")
        target = (path.parent / name).resolve() if name else path
        if not target.exists():
            broken.append(f"{link}: no file {name}")
        elif fragment and target.suffix == ".md" and fragment not in anchors(target):
            broken.append(f"{link}: no heading '{fragment}' in {target.name}")
    return broken


def test_the_anchor_rule_on_github_examples(tmp_path: Path) -> None:
    assert anchor("A process that runs one command (`planning.cli.process`, stop 106)") == (
        "a-process-that-runs-one-command-planningcliprocess-stop-106"
    )
    refinement = "Refinement (`RefinementSettings`, `refine_stall`)"
    assert anchor(refinement) == "refinement-refinementsettings-refine_stall"
    page = tmp_path / "page.md"
    page.write_text("# Title\n\n## Notes\n\n```sh\n# not a heading\n```\n\n## Notes\n")
    assert anchors(page) == {"title", "notes", "notes-1"}


def test_a_broken_link_is_found(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    (tmp_path / "other.md").write_text("# Other\n")
    page.write_text(
        "# Page\n\n[fine](other.md#other) [self](#page) `quoted](1)` [web](https://example.org)\n"
        "[gone](missing.md) [heading](other.md#nowhere) [here](#nowhere)\n"
    )
    assert [entry.split(":")[0] for entry in broken_links(page)] == [
        "missing.md",
        "other.md#nowhere",
        "#nowhere",
    ]


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda path: path.name)
def test_every_relative_link_leads_somewhere(document: Path) -> None:
    assert broken_links(document) == []


BENCHMARKS = ROOT / "docs" / "benchmarks.md"
SCRIPT = re.compile(r"(?<![\w/])(?:scripts/)?(\w+\.py)")
FLAG = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")


def now_commands() -> list[str]:
    """The code spans of docs/benchmarks.md's Now table's "reprint with" column, row by row joined."""
    text = BENCHMARKS.read_text()
    table = text.split("\n## Now\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in table.splitlines() if line.startswith("| ")]  # not the header's rule
    column = [cell.strip() for cell in rows[0].strip("|").split("|")].index("reprint with")
    return [" ".join(re.findall(r"`([^`]+)`", row.strip("|").split(" | ")[column])) for row in rows[1:]]


def make_targets() -> set[str]:
    """The Makefile's targets."""
    return set(re.findall(r"^([\w-]+):", (ROOT / "Makefile").read_text(), re.M))


def test_the_now_table_has_a_command_in_every_row() -> None:
    commands = now_commands()
    assert len(commands) >= 20 and all(commands), commands


def test_each_command_of_the_now_table_names_what_exists() -> None:
    targets, missing = make_targets(), []
    for command in now_commands():
        missing += [f"make {t}" for t in re.findall(r"\bmake ([\w-]+)", command) if t not in targets]
        missing += [name for name in SCRIPT.findall(command) if not (ROOT / "scripts" / name).exists()]
        missing += [path for path in re.findall(r"tests/\w+\.py", command) if not (ROOT / path).exists()]
    assert missing == []


@pytest.mark.slow
def test_each_script_of_the_now_table_takes_the_options_it_is_given() -> None:
    """Every ``--option`` a row gives a script is one its ``--help`` lists (a new process per script)."""
    options: dict[str, set[str]] = {}
    for command in now_commands():
        # a row's options belong to the script named before them (`a.py --x`, then `b.py --y`)
        for part in re.split(r"(?<![\w/])(?=(?:scripts/)?\w+\.py)", command):
            script = SCRIPT.match(part.strip())
            if script and (ROOT / "scripts" / script.group(1)).exists():
                options.setdefault(script.group(1), set()).update(FLAG.findall(part))
    unknown = []
    for name, given in sorted(options.items()):
        shown = subprocess.run(
            [sys.executable, str(ROOT / "scripts" / name), "--help"],
            capture_output=True,
            text=True,
            timeout=120,
            check=True,
        ).stdout
        unknown += [f"{name} {flag}" for flag in sorted(given) if flag not in FLAG.findall(shown)]
    assert unknown == []
