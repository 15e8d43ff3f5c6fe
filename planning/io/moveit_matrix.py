"""A MoveIt allowed-collision matrix as a scene file's ``allowed_collisions``: robot-link pairs.

A pair is allowed when either of its two entries is ``true``; a default entry ``true`` allows
its name with every link. Contact between a link and an object has no counterpart (the scene's
obstacles are always checked) and is refused.
"""

from __future__ import annotations

from planning.io.moveit_messages import AllowedCollisionMatrix, MoveItImportError


def allowed_pairs(matrix: AllowedCollisionMatrix, links: set[str], objects: set[str]) -> list[list[str]]:
    """The allowed-collision matrix's robot-link pairs; contact with an object is refused.

    Entries of names that are neither links nor objects change nothing (as in MoveIt); the
    caller lists them as ignored.
    """
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
    for name, value in zip(matrix.default_entry_names, matrix.default_entry_values, strict=False):
        if value:
            pairs |= {tuple(sorted((name, link))) for link in links if link != name}
    touching = sorted(p for p in pairs if (p[0] in objects) != (p[1] in objects))
    if touching:
        raise MoveItImportError(
            f"allowed_collision_matrix allows {list(touching[0])} to touch; "
            "contact with an object is not supported"
        )
    return [list(p) for p in sorted(pairs) if p[0] in links and p[1] in links]
