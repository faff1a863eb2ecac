"""The README's examples run as written: its fenced shell, Python and C blocks in order, in a clean folder,
as a new user runs them after ``make demo``; every ``humanmpc-gen`` command line it shows parses."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from humanmpc.cli import build_parser
from humanmpc.codegen.spec import Spec, resolve_spec
from humanmpc.eval.extras import install_line

REPO = Path(__file__).resolve().parent.parent
README = REPO / "README.md"
FENCE = re.compile(r"```(\w+)\n(.*?)```", flags=re.DOTALL)


def blocks(lang: str) -> list[str]:
    return [code for kind, code in FENCE.findall(README.read_text()) if kind == lang]


def test_readme_spec_is_the_default_spec() -> None:
    (spec_text,) = blocks("yaml")
    assert resolve_spec(yaml.safe_load(spec_text)) == Spec()


def shell_commands(code: str) -> list[str]:
    """The commands of a shell block, comments stripped, continuation lines joined."""
    joined = code.replace("\\\n", " ")
    return [line.split("  #")[0].strip() for line in joined.splitlines() if line.strip()]


def make_demo_command() -> str:
    """What ``make demo`` runs after its setup (the Makefile's demo recipe), with the venv's humanmpc-gen."""
    recipe = re.search(r"^demo: venv\n\t(.+)$", (REPO / "Makefile").read_text(), flags=re.MULTILINE)
    assert recipe, "the Makefile's demo target"
    return recipe[1].replace("$(GEN)", "humanmpc-gen")


def run_shell(command: str, cwd: Path, env: dict[str, str]) -> str:
    """One README command. Those that set up the checkout's .venv are what this suite's environment already
    is: ``source .venv/bin/activate`` (humanmpc-gen is on PATH) and the campaign extra's pip line (installed
    by make test; the line is the one a command that lacks it prints)."""
    if command == "source .venv/bin/activate":
        return ""
    if command.startswith("pip install"):
        assert command.split()[:3] == ["pip", "install", "-e"] and "[campaign]" in command
        assert "[campaign]" in install_line()
        return ""
    done = subprocess.run(command, shell=True, cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"README: `{command}` failed ({done.returncode}):\n{done.stdout}\n{done.stderr}"
    return done.stdout


@pytest.mark.slow
def test_readme_blocks_run_in_order_in_a_clean_folder(tmp_path: Path) -> None:
    """make demo's command, then every fenced block in the README's order: shell commands run, Python blocks
    run together (the controller's reuses the solver's imports), the C block is saved as example.c (as the
    README says) for the shell block after it."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
           "MPLBACKEND": "Agg"}
    env.pop("PYTHONPATH", None)
    shutil.copy(REPO / "Makefile", tmp_path / "Makefile")  # the checkout's files the commands read
    outputs = [run_shell(make_demo_command(), tmp_path, env)]
    python_code = ""
    for kind, code in FENCE.findall(README.read_text()):
        if kind == "sh":
            if python_code:
                outputs.append(run_shell(f"{shlex.quote(sys.executable)} readme_example.py", tmp_path, env))
                python_code = ""
            outputs.extend(run_shell(c, tmp_path, env) for c in shell_commands(code))
        elif kind == "python":
            python_code += code
            (tmp_path / "readme_example.py").write_text(python_code)
        elif kind == "c":
            (tmp_path / "example.c").write_text(code)
    if python_code:
        outputs.append(run_shell(f"{shlex.quote(sys.executable)} readme_example.py", tmp_path, env))
    out = "\n".join(outputs)
    assert "Dims(nx=4, nu=2, N=50, nh=10, ng=11" in out  # the solver's example
    assert "following" in out and "(51, 4)" in out  # the controller's outcome and plan
    assert "u0 = [" in out and "stop: no" in out  # the C example
    assert (tmp_path / "out" / "corridor.png").is_file() and (tmp_path / "out" / "first" / "report.md").is_file()


def command_lines() -> list[str]:
    """Every ``humanmpc-gen ...`` line of the README, fenced or indented, continuation lines joined."""
    text = README.read_text().replace("\\\n", " ")
    return [m.strip() for m in re.findall(r"^\s*(humanmpc-gen [^#\n]*)", text, flags=re.MULTILINE)]


PLACEHOLDERS = {"SPEC": "spec.yaml", "DIR": "gen", "OUT": "out"}


def test_every_readme_command_line_parses() -> None:
    """Placeholders (``DIR``, ``[SPEC]``, ``[-o OUT]``) filled in; ``...`` (the options of the line above) dropped."""
    parser = build_parser()
    lines = command_lines()
    assert len(lines) > 15
    for line in lines:
        words = [w for w in shlex.split(re.sub(r"\[([^\]=]*)\]", r"\1", line.replace("...", " "))) if w]
        words = [PLACEHOLDERS.get(w, w) for w in words[1:]]
        try:
            parser.parse_args(words)
        except SystemExit as err:
            pytest.fail(f"README: `{line}` does not parse ({err})")
