"""The manifest of a generated package: one typed record (humanmpc.codegen.manifest), written by the
generator and read by every reader through it, with errors that name the key."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import humanmpc
from humanmpc.codegen.build import BuildError, read_manifest
from humanmpc.codegen.manifest import MANIFEST, Manifest, ManifestError, ManifestMissingError
from humanmpc.planners.solver_cache import SolverDirError, check_solver_dir
from humanmpc.status import GENERATOR_TABLES

REPO = Path(__file__).resolve().parents[1]


def test_the_written_manifest_reads_back_to_the_same_json(paper_dir: Path) -> None:
    data = json.loads((paper_dir / MANIFEST).read_text())
    m = Manifest.read(paper_dir)
    assert m.to_json() == data
    assert m.dims.N == 50 and m.real == "double" and m.library == f"build/lib{m.name}.so"
    assert {k: tuple(v) for k, v in m.statuses.items()} == GENERATOR_TABLES


@pytest.mark.parametrize(("edit", "message"), [
    (lambda d: d["dims"].pop("nh"), r"'dims\.nh' is missing"),
    (lambda d: d["dims"].update(N="50"), r"'dims\.N' must be an integer, got str"),
    (lambda d: d.update(real="half"), r"'real' is 'half'"),
    (lambda d: d["functions"][0]["inputs"].append(["x", -1, 1]), r"'functions\[0\]\.inputs\[\d+\]' must be"),
    (lambda d: d["statuses"]["stop_reason"].append([1, "x", 2]), r"'statuses\.stop_reason\[\d+\]' must be"),
    (lambda d: d.pop("params"), "no parameter table"),
])
def test_a_damaged_manifest_names_the_key_and_says_to_regenerate(paper_dir: Path, edit, message: str) -> None:  # type: ignore[no-untyped-def]
    data = json.loads((paper_dir / MANIFEST).read_text())
    edit(data)
    with pytest.raises(ManifestError, match=message) as err:
        Manifest.from_json(data)
    assert "generate the package again" in str(err.value)


def test_every_reader_reports_a_missing_or_damaged_manifest_in_its_own_error(tmp_path: Path) -> None:
    with pytest.raises(ManifestMissingError):
        Manifest.read(tmp_path / "nothing")
    with pytest.raises(BuildError, match="does not exist"):
        read_manifest(tmp_path / "nothing")
    (tmp_path / MANIFEST).write_text(json.dumps({"name": "ok"}))
    with pytest.raises(BuildError, match=r"'generator' is missing|'real' is missing"):
        read_manifest(tmp_path)
    with pytest.raises(SolverDirError, match="is not a humanmpc manifest"):
        check_solver_dir(tmp_path)
    with pytest.raises(humanmpc.LoadError, match="is not a humanmpc manifest"):
        humanmpc.load(tmp_path)


def test_a_package_with_other_status_tables_is_refused_at_load(paper_dir: Path, tmp_path: Path) -> None:
    import shutil

    d = tmp_path / "other"
    shutil.copytree(paper_dir, d)
    data = json.loads((d / MANIFEST).read_text())
    data["statuses"]["stop_reason"][1][1] = "renamed"
    (d / MANIFEST).write_text(json.dumps(data))
    with pytest.raises(humanmpc.LoadError, match="'stop_reason' table"):
        humanmpc.load(d, build_if_needed=False)


def test_a_loaded_solver_carries_its_packages_status_enums(paper: humanmpc.Solver) -> None:
    assert paper.statuses is not None
    assert [(int(s), s.name) for s in paper.statuses.stop_reason] == [(int(s), s.name) for s in humanmpc.StopReason]
    assert paper.statuses.stop_reason(1).message == humanmpc.StopReason(1).message


def test_only_the_manifest_module_opens_manifest_json() -> None:
    """No reader parses the file its own way: json.load of a manifest only in codegen/manifest.py."""
    pattern = re.compile(r"json\.loads?\([^\n]*(manifest|MANIFEST)")
    files = [*(REPO / "python").rglob("*.py"), *(REPO / "codegen").glob("*.py")]
    assert [p for p in files if pattern.search(p.read_text()) and p.name != "manifest.py"] == []
