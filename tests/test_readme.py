"""The README's examples run as written."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

import humanmpc
from humanmpc.codegen.spec import Spec, resolve_spec

README = Path(__file__).resolve().parent.parent / "README.md"


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README.read_text(), flags=re.DOTALL)


def test_readme_spec_is_the_default_spec() -> None:
    (spec_text,) = blocks("yaml")
    assert resolve_spec(yaml.safe_load(spec_text)) == Spec()


def test_readme_python_example_runs(paper: humanmpc.Solver, paper_dir: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    (code,) = blocks("python")
    exec(compile(code.replace('"generated/paper"', repr(str(paper_dir))), "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "Dims(nx=4, nu=2, N=50, nh=10, ng=11" in out
