"""A MoveIt allowed-collision matrix as a scene file's ``allowed_collisions``: robot-link pairs.

A pair is allowed when either of its two entries is ``true``; a default entry ``true`` allows
its name with every other name the matrix has no entry with, but one whose default is ``false``
(MoveIt's rule: the pair's entry comes first, and of two defaults ``false`` wins). Contact
between a link and an object, of the world or attached, is the object's ``touch_links``;
between the attached object and one of the world, the payload's ``touch_obstacles``
(:class:`AllowedContacts`); two objects of the world are never checked against each other.
"""

from __future__ import annotations

from planning.io.moveit_messages import AllowedCollisionMatrix, MoveItImportError


class AllowedContacts:
    """The pairs of names a matrix allows to touch (module docstring), read once.

    Its entries' pairs are gathered when it is built (the matrix's size squared, once); a pair
    without an entry is decided by the defaults when asked. An import asks it for every object
    of the scene: the matrix is not read again for each.

    Raises:
        MoveItImportError: the entries' values are not a square matrix of its names.
    """

    def __init__(self, matrix: AllowedCollisionMatrix) -> None:
        names = matrix.entry_names
        if len(matrix.entry_values) != len(names) or any(
            len(row) != len(names) for row in matrix.entry_values
        ):
            raise MoveItImportError(
                f"allowed_collision_matrix: {len(names)} names need a {len(names)} x {len(names)} matrix"
            )
        self._entries = {
            (names[i], names[j])
            for i in range(len(names))
            for j in range(i + 1, len(names))
            if matrix.entry_values[i][j] or matrix.entry_values[j][i]
        }
        self._listed = set(names)
        self._default = dict(zip(matrix.default_entry_names, matrix.default_entry_values, strict=False))

    def allows(self, a: str, b: str) -> bool:
        """Whether ``a`` and ``b`` may touch: the pair's entry, else the defaults (``false`` wins)."""
        if a == b:
            return False
        if a in self._listed and b in self._listed:  # the pair's own entry comes first
            return (a, b) in self._entries or (b, a) in self._entries
        default = self._default
        return bool(default.get(a) and default.get(b, True)) or bool(default.get(b) and default.get(a, True))

    def allowed_with(self, name: str, candidates: set[str]) -> set[str]:
        """The ``candidates`` (links, or objects) allowed to touch ``name`` (an object's id)."""
        return {c for c in candidates if self.allows(name, c)}

    def link_pairs(self, links: set[str]) -> list[list[str]]:
        """The robot-link pairs allowed to touch, each sorted, in order: a scene's ``allowed_collisions``.

        Entries of names that are neither links nor objects change nothing (as in MoveIt); the
        caller lists them as ignored.
        """
        pairs = {tuple(sorted(pair)) for pair in self._entries if set(pair) <= links}
        for name in (n for n in links if self._default.get(n)):  # a default true, with the others
            pairs |= {tuple(sorted((name, o))) for o in links if self.allows(name, o)}
        return [list(pair) for pair in sorted(pairs)]
