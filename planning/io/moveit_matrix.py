"""A MoveIt allowed-collision matrix as a scene file's ``allowed_collisions``: robot-link pairs.

A pair is allowed when either of its two entries is ``true``; a default entry ``true`` allows
its name with every other name the matrix has no entry with, but one whose default is ``false``
(MoveIt's rule: the pair's entry comes first, and of two defaults ``false`` wins). Contact
between a link and an object, of the world or attached, is the object's ``touch_links``;
between the attached object and one of the world, the payload's ``touch_obstacles``
(:func:`allowed_with`); two objects of the world are never checked against each other.
"""

from __future__ import annotations

from planning.io.moveit_messages import AllowedCollisionMatrix, MoveItImportError


def _pairs(matrix: AllowedCollisionMatrix, others: set[str]) -> set[tuple[str, str]]:
    """Every pair of names the matrix allows to touch, sorted within the pair; defaults with ``others``."""
    names = matrix.entry_names
    if len(matrix.entry_values) != len(names) or any(len(row) != len(names) for row in matrix.entry_values):
        raise MoveItImportError(
            f"allowed_collision_matrix: {len(names)} names need a {len(names)} x {len(names)} matrix"
        )
    pairs = {
        tuple(sorted((names[i], names[j])))
        for i in range(len(names))
        for j in range(i + 1, len(names))
        if matrix.entry_values[i][j] or matrix.entry_values[j][i]
    }
    listed = set(names)
    default = dict(zip(matrix.default_entry_names, matrix.default_entry_values, strict=False))
    for name in (n for n, allowed in default.items() if allowed):  # not where the pair has an entry,
        pairs |= {  # nor where the other's default is false
            tuple(sorted((name, o)))
            for o in others
            if o != name and not {name, o} <= listed and default.get(o, True)
        }
    return {(a, b) for a, b in pairs}


def allowed_pairs(matrix: AllowedCollisionMatrix, links: set[str]) -> list[list[str]]:
    """The allowed-collision matrix's robot-link pairs.

    Entries of names that are neither links nor objects change nothing (as in MoveIt); the
    caller lists them as ignored.
    """
    pairs = _pairs(matrix, links)
    return [list(p) for p in sorted(pairs) if p[0] in links and p[1] in links]


def allowed_with(matrix: AllowedCollisionMatrix, name: str, candidates: set[str]) -> set[str]:
    """The ``candidates`` (links, or objects) the matrix allows to touch ``name`` (an object's id)."""
    pairs = _pairs(matrix, candidates | {name})
    return {a if b == name else b for a, b in pairs if name in (a, b)} & candidates
