"""The kernels' disk cache in a source checkout: dropped when a file that compiles a kernel changes."""

from __future__ import annotations

from pathlib import Path

from cpr_kin.common.compiled import forget_stale_kernels


def checkout(root: Path) -> list[Path]:
    """A checkout of one package: a kernel's file, another file, and the kernel's cached code."""
    (root / ".git").mkdir(parents=True)
    package = root / "pkg"
    (package / "__pycache__").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "kernels.py").write_text(
        "from cpr_kin.common.compiled import njit\n\n\ndef f(x):\n    return x\n"
    )
    (package / "other.py").write_text("LIMIT = 1.0\n")
    return cached(package)


def cached(package: Path) -> list[Path]:
    files = [package / "__pycache__" / name for name in ("kernels.f-4.py311.nbi", "kernels.f-4.py311.1.nbc")]
    for path in files:
        path.write_bytes(b"compiled")
    return files


def test_a_kernels_file_changed_drops_the_cached_kernels(tmp_path: Path) -> None:
    stamp = tmp_path / "stamp.txt"
    files = checkout(tmp_path / "repo")
    package = tmp_path / "repo" / "pkg"
    assert forget_stale_kernels(tmp_path / "repo", stamp)  # never seen: what is cached may be stale
    assert not any(path.exists() for path in files)
    files = cached(package)
    assert not forget_stale_kernels(tmp_path / "repo", stamp)  # nothing changed
    (package / "other.py").write_text("LIMIT = 2.0\n")  # a file that compiles nothing
    assert not forget_stale_kernels(tmp_path / "repo", stamp)
    assert all(path.exists() for path in files)
    (package / "kernels.py").write_text((package / "kernels.py").read_text().replace("return x", "return 2"))
    assert forget_stale_kernels(tmp_path / "repo", stamp)
    assert not any(path.exists() for path in files)


def test_outside_a_checkout_nothing_is_touched(tmp_path: Path) -> None:
    files = checkout(tmp_path / "repo")
    (tmp_path / "repo" / ".git").rmdir()
    assert not forget_stale_kernels(tmp_path / "repo", tmp_path / "stamp.txt")
    assert all(path.exists() for path in files)


def test_a_stamp_that_cannot_be_kept_is_no_error(tmp_path: Path) -> None:
    checkout(tmp_path / "repo")
    (tmp_path / "blocker").write_text("a file where the stamp's folder would be")
    assert not forget_stale_kernels(tmp_path / "repo", tmp_path / "blocker" / "stamp.txt")
