"""The README's examples run as written."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from humanmpc.codegen.spec import Spec, resolve_spec

README = Path(__file__).resolve().parent.parent / "README.md"


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README.read_text(), flags=re.DOTALL)


def test_readme_spec_is_the_default_spec() -> None:
    (spec_text,) = blocks("yaml")
    assert resolve_spec(yaml.safe_load(spec_text)) == Spec()


def test_readme_python_examples_run(default_dir: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """The solver's example, then the controller's (which reuses its imports), on the default spec."""
    solver_code, controller_code = blocks("python")
    code = (solver_code + controller_code).replace('"generated/paper"', repr(str(default_dir)))
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "Dims(nx=4, nu=2, N=50, nh=10, ng=11" in out
    assert "following" in out and "(51, 4)" in out  # the controller's outcome and plan
