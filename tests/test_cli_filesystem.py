"""File-system errors while generating: reported in one line naming the path, nothing half written."""

from __future__ import annotations

import errno
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from humanmpc import cli
from humanmpc.codegen.casadi_emit import check_complete
from humanmpc.codegen.generate import GenerateError, write_atomically


@contextmanager
def tmpfs(where: Path, options: str) -> Iterator[Path]:
    """A tmpfs mounted at where with options (ro, size=...): root runs the suite, so chmod cannot make a
    folder read-only; a mount can. Skips when mounting is not permitted (no root, a container without
    CAP_SYS_ADMIN)."""
    where.mkdir()
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)], capture_output=True,
                          text=True, check=False)
    if proc.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here ({proc.stderr.strip() or proc.returncode}): needs root")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=False)


@pytest.mark.parametrize(("options", "why"), [
    ("ro,size=1m", "Read-only file system"),
    ("size=16k", "CasADi's output is cut short"),  # CasADi's own writes fail silently: caught by check_complete
    ("size=64k", "No space left on device"),
])
def test_generate_onto_a_read_only_or_full_file_system_says_so_in_one_line_and_leaves_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], options: str, why: str) -> None:
    with tmpfs(tmp_path / "mnt", options) as mnt:
        out = mnt / "sub" / "solver"
        assert cli.main(["generate", "-o", str(out)]) == 1
        err = capsys.readouterr().err
        assert f"humanmpc-gen: cannot write {out}: {why}" in err and "nothing was written" in err, err
        assert "Traceback" not in err
        assert list(mnt.iterdir()) == []  # no partial folder, no parent left behind


def test_an_os_error_while_writing_is_a_generate_error_naming_the_path_and_nothing_is_left(tmp_path: Path) -> None:
    dest = tmp_path / "a" / "b" / "solver"

    def fill_up(tmp: Path) -> None:
        (tmp / "half.c").write_text("int x;")
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp / "big.c"))

    with pytest.raises(GenerateError, match=f"cannot write {dest}: No space left on device") as info:
        write_atomically(dest, fill_up, force=False)
    assert "big.c" in str(info.value) and "nothing was written" in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_a_casadi_file_cut_short_is_detected(tmp_path: Path) -> None:
    whole = tmp_path / "m.c"
    whole.write_text('int f(void);\n#ifdef __cplusplus\n} /* extern "C" */\n#endif\n')
    check_complete(whole)
    cut = tmp_path / "cut.c"
    cut.write_text(whole.read_text()[:20])
    with pytest.raises(OSError, match="cut short"):
        check_complete(cut)


def test_generate_into_an_existing_folder_refuses_before_saying_it_is_generating(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "nav5"
    out.mkdir()
    assert cli.main(["generate", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "already exists: pass --force" in err
    assert "generating" not in err
