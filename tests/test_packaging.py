"""The package as users get it: a wheel that works outside the checkout, and layers that point one way.

The layers are import-linter contracts in pyproject.toml ([tool.importlinter]). The checkout keeps the
generator in codegen/ beside the package in python/ (the product's top-level folders), which
import-linter cannot follow, so the check runs on the tree as a wheel lays it out (humanmpc/ with
humanmpc/codegen/ inside).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest
import tomllib

from .conftest import REPO_ROOT

CONTRACTS = (
    "The generator (humanmpc.codegen) imports nothing of humanmpc outside itself",
    "Layers: codegen -> the solver's face -> sim -> planners -> eval | compare",
    "No import cycles between the modules of any package",
)


def _clean_env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(extra)
    return env


def _stage_package(root: Path) -> Path:
    """humanmpc/ as a wheel lays it out, from the checkout's python/ and codegen/."""
    pkg = root / "humanmpc"
    ignore = shutil.ignore_patterns("__pycache__")
    shutil.copytree(REPO_ROOT / "python", pkg, ignore=ignore)
    shutil.copytree(REPO_ROOT / "codegen", pkg / "codegen", ignore=ignore)
    return pkg


def _checkout_modules() -> set[str]:
    """humanmpc's modules and subpackages as the checkout holds them (what a wheel must carry)."""
    names = set()
    for root, prefix in ((REPO_ROOT / "python", "humanmpc"), (REPO_ROOT / "codegen", "humanmpc.codegen")):
        for f in root.rglob("*.py"):
            parts = list(f.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            if parts:
                names.add(".".join([prefix, *parts]))
    return names | {"humanmpc.codegen", "humanmpc.codegen.templates", "humanmpc.codegen.c_runtime"}


def _lint_imports(stage: Path) -> subprocess.CompletedProcess[str]:
    exe = Path(sys.executable).parent / "lint-imports"
    if not exe.is_file():
        pytest.fail("lint-imports is not installed: `make test` installs import-linter (the dev extra)")
    return subprocess.run([str(exe), "--config", str(REPO_ROOT / "pyproject.toml"), "--no-cache"], cwd=stage,
                          env=_clean_env(PYTHONPATH=str(stage)), capture_output=True, text=True, timeout=300,
                          check=False)


def test_every_import_layer_contract_is_kept(tmp_path: Path) -> None:
    stage = tmp_path / "stage"
    _stage_package(stage)
    proc = _lint_imports(stage)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    contracts = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    assert f"{len(contracts)} kept, 0 broken" in proc.stdout, proc.stdout
    assert "Analyzed" in proc.stdout


@pytest.mark.parametrize(("module", "line", "contract"), [
    ("codegen/spec.py", "from ..solver import Solver", 0),          # the generator reaching into the rest
    ("sim/world.py", "from ..eval import metrics", 1),               # a lower layer reaching up
    ("planners/mpc.py", "from . import registry", 2),                # registry imports mpc: a cycle
])
def test_a_reverse_import_breaks_its_contract(tmp_path: Path, module: str, line: str, contract: int) -> None:
    stage = tmp_path / "stage"
    pkg = _stage_package(stage)
    with (pkg / module).open("a") as f:
        f.write(f"\n{line}  # noqa\n")
    proc = _lint_imports(stage)
    assert proc.returncode != 0
    summary = " ".join(proc.stdout.split())
    assert f"{CONTRACTS[contract]}" in summary
    after = summary.split(CONTRACTS[contract], 1)[1]
    assert after.find("BROKEN") != -1 and (after.find("KEPT") == -1 or after.find("BROKEN") < after.find("KEPT"))


@pytest.mark.slow
def test_the_wheel_installed_in_a_fresh_venv_generates_builds_loads_and_steps_a_solver(tmp_path: Path) -> None:
    # from a copy of what the wheel is made of: setuptools leaves build/ in the source folder, and a
    # stale build/lib would carry modules the checkout no longer has
    src = tmp_path / "src"
    for part in ("python", "codegen", "templates", "c_runtime"):
        shutil.copytree(REPO_ROOT / part, src / part, ignore=shutil.ignore_patterns("__pycache__"))
    for part in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO_ROOT / part, src / part)
    wheel_dir = tmp_path / "wheel"
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                            "-w", str(wheel_dir), str(src)], cwd=tmp_path, env=_clean_env(),
                           capture_output=True, text=True, timeout=600, check=False)
    assert build.returncode == 0, build.stderr[-3000:]
    wheels = list(wheel_dir.glob("humanmpc-*.whl"))
    assert len(wheels) == 1
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True, clear=True).create(env_dir)
    python = env_dir / "bin" / "python"
    install = subprocess.run([str(python), "-m", "pip", "install", "-q", str(wheels[0])], cwd=tmp_path,
                             env=_clean_env(), capture_output=True, text=True, timeout=1200, check=False)
    assert install.returncode == 0, install.stderr[-3000:]

    work = tmp_path / "elsewhere"
    work.mkdir()
    gen = env_dir / "bin" / "humanmpc-gen"
    (work / "tiny.yaml").write_text("name: tiny\nhorizon: {N: 10, T: 1.0}\nhumans: {max: 2}\n")
    for cmd in (["generate", "tiny.yaml", "-o", "out/tiny"], ["build", "out/tiny"], ["ros", "out/tiny"]):
        proc = subprocess.run([str(gen), *cmd], cwd=work, env=_clean_env(), capture_output=True, text=True,
                              timeout=600, check=False)
        assert proc.returncode == 0, proc.stderr[-3000:]
    # the ROS node's templates are package data too (templates/ros/)
    assert (work / "out" / "tiny_ros_src" / "tiny_ros" / "src" / "tiny_node.cpp").is_file()
    # every module of the checkout is in the wheel and imports (acados_peer runs only in acados' venv; the
    # ROS 2 node's modules, without the ros2 extra, refuse with the pip line that installs it)
    walk = ("import importlib, pkgutil, humanmpc\n"
            "names = sorted(m.name for m in pkgutil.walk_packages(humanmpc.__path__, 'humanmpc.'))\n"
            "for n in names:\n"
            "    if n.endswith(('acados_peer', '__main__')):\n"
            "        continue\n"
            "    try:\n"
            "        importlib.import_module(n)\n"
            "    except ImportError as err:  # the ros2 extra is not installed here: its modules name it\n"
            "        assert n.startswith('humanmpc.ros2.') and \"humanmpc[ros2]\" in str(err), (n, err)\n"
            "print(' '.join(names))\n")
    proc = subprocess.run([str(python), "-c", walk], cwd=work, env=_clean_env(), capture_output=True, text=True,
                          timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert set(proc.stdout.split()) == _checkout_modules()
    help_proc = subprocess.run([str(gen), "--help"], cwd=work, env=_clean_env(), capture_output=True, text=True,
                               timeout=120, check=False)
    assert help_proc.returncode == 0 and "firmware-report" in help_proc.stdout
    script = (
        "import numpy as np, humanmpc, pathlib\n"
        "assert 'site-packages' in humanmpc.__file__, humanmpc.__file__\n"
        "s = humanmpc.load('out/tiny')\n"
        "pred = np.stack([[[3.0, 0.4 - 0.1 * n]] for n in range(11)])\n"
        "r = s.step([0, 0, 0, 0.5], [5, 0, 0, 0.8], [[3.0, 0.4]], pred, obstacle=[4.0, 1.0])\n"
        "assert r.status_name == 'solved' and not r.stop, r\n"
        "assert np.all(np.isfinite(r.u0)) and r.x.shape == (11, 4)\n"
        "print('stepped', r.u0.tolist())\n"
    )
    proc = subprocess.run([str(python), "-c", script], cwd=work, env=_clean_env(), capture_output=True, text=True,
                          timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "stepped" in proc.stdout
    assert REPO_ROOT.as_posix() not in proc.stdout + proc.stderr
