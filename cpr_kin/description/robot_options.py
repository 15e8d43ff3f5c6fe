"""Checks of what a :class:`~cpr_kin.description.loading.RobotSpec` asks for, before and during its load.

Each refuses an option of the wrong kind or a name the URDF does not have with one
:class:`~cpr_kin.common.errors.UrdfError` naming the option, its value and what is allowed, where it
would otherwise fail deep inside the load (a string of joint names split into letters, an
integer frame reaching Pinocchio's C++ signature) or be taken for something else (a misspelt
tool frame on a tree of several arms read as no tool frame at all).
"""

from __future__ import annotations

from numbers import Real
from pathlib import Path
from typing import Any, Protocol

import pinocchio as pin

from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import listed, shown

NAME_OPTIONS = ("joints", "effector_links", "wrist_joints", "limits_names")
"""The options that hold a sequence of names."""
OPTIONAL = ("joints", "effector_links")
"""Those of :data:`NAME_OPTIONS` that may be ``None`` (a default chosen at the load)."""
SHOWN_CHARS = 60
"""Longest rendering of an option's value in a message (a tuple of names runs long)."""
SHOWN_LINKS = 30
"""Most of a URDF's links a message about a missing tool frame lists (a humanoid has 150 frames)."""


class Options(Protocol):
    """What :func:`check_options` reads of a :class:`~cpr_kin.description.loading.RobotSpec`.

    Besides :data:`NAME_OPTIONS`, read by name; each as the user gave it, maybe of the wrong kind.
    """

    @property
    def tcp(self) -> Any:
        """The tool frame's name."""

    @property
    def held(self) -> Any:
        """``(joint, value)`` pairs."""

    @property
    def package_dirs(self) -> Any:
        """The folders of the URDF's packages."""


def check_options(spec: Options) -> None:
    """Refuse options of the wrong kind, naming the option and its value.

    Raises:
        UrdfError: a name option that is not a sequence of non-empty strings, a ``tcp`` that
            is not a non-empty string, ``held`` values that are not numbers, or package
            folders that are not paths.
    """
    for key in NAME_OPTIONS:
        value = getattr(spec, key)
        if value is None and key in OPTIONAL:
            continue
        if not isinstance(value, tuple) or not all(isinstance(n, str) and n for n in value):
            raise UrdfError(
                f"{key} = {shown(value, SHOWN_CHARS)} must be a sequence of names (non-empty strings)"
            )
    if spec.tcp is not None and not (isinstance(spec.tcp, str) and spec.tcp):
        raise UrdfError(
            f"tcp = {shown(spec.tcp, SHOWN_CHARS)} must be a frame's name (a non-empty string) or None"
        )
    held_ok = isinstance(spec.held, tuple) and all(
        isinstance(pair, tuple)
        and len(pair) == 2
        and isinstance(pair[0], str)
        and isinstance(pair[1], Real)
        and not isinstance(pair[1], bool)
        for pair in spec.held
    )
    if not held_ok:
        raise UrdfError(f"held = {shown(spec.held, SHOWN_CHARS)} must map joint names to numbers [rad or m]")
    if not isinstance(spec.package_dirs, tuple) or not all(
        isinstance(d, str | Path) for d in spec.package_dirs
    ):
        raise UrdfError(
            f"package_dirs = {shown(spec.package_dirs, SHOWN_CHARS)} must be a sequence of folders"
        )


def check_not_one_name(key: str, value: Any) -> None:
    """Refuse one name (a string or a path) given where a sequence of them belongs.

    Raises:
        UrdfError: naming the option and how to give it.
    """
    if isinstance(value, str | Path):
        raise UrdfError(
            f"{key} = {shown(value, SHOWN_CHARS)} must be a sequence, not one name: give [{str(value)!r}]"
        )


def check_tcp(tcp: str | None, model: Any, path: Path) -> None:
    """Refuse a ``tcp`` the URDF's Pinocchio ``model`` does not have, naming its closest frames.

    Checked before the planned joints are chosen from it: with no such frame a tree of
    several arms would be refused for having no single arm, as if no tool had been named.

    Raises:
        UrdfError: naming the frame, up to three close names (of the URDF's frames) and its
            links (the first :data:`SHOWN_LINKS` of them, alphabetically, and how many there are).
    """
    if tcp is None or model.existFrame(tcp):
        return
    from difflib import get_close_matches  # a message's, not every load's (a new process's start-up)

    # every frame but Pinocchio's own root, 'universe', which no URDF names
    named = sorted({f.name for f in list(model.frames)[1:]})
    close = get_close_matches(tcp, named, n=3, cutoff=0.5)
    hint = f"did you mean {', '.join(repr(name) for name in close)}? " if close else ""
    links = sorted({f.name for f in model.frames if f.type == pin.FrameType.BODY})
    raise UrdfError(
        f"URDF '{path}' has no link or frame named '{tcp}' (the tool frame, tcp); "
        f"{hint}its links are {listed(links, SHOWN_LINKS)}"
    )
