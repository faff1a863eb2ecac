"""The generated package: compiles cleanly with gcc and clang, allocates nothing, links twice, builds on its own."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import humanmpc
from humanmpc import cli
from humanmpc.codegen.build import BuildError, build
from humanmpc.codegen.generate import GenerateError, generate, write_atomically
from humanmpc.codegen.spec import Spec, resolve_spec

from .conftest import QUIET, make_solver, require_tool

STRICT = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-Wshadow", "-Wdouble-promotion"]


def run(cmd: list[str], cwd: Path | None = None) -> str:
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout


@pytest.mark.parametrize("compiler", ["gcc", "clang"])
def test_generated_c_compiles_warning_free_as_c99(paper_dir: Path, tmp_path: Path, compiler: str) -> None:
    cc = require_tool(compiler)
    for src in ("paper.c", "paper_model.c"):
        run([cc, *STRICT, "-O2", "-I", str(paper_dir), "-c", str(paper_dir / src), "-o", str(tmp_path / "x.o")])


def test_library_links_no_allocator(paper_dir: Path) -> None:
    nm = require_tool("nm")
    for lib in ("libpaper.a", "libpaper.so"):
        symbols = run([nm, "-A", str(paper_dir / "build" / lib)])
        for fn in ("malloc", "calloc", "realloc", "free"):
            assert f" {fn}" not in symbols and f" {fn}@" not in symbols, f"{lib} references {fn}"


def test_every_exported_symbol_carries_the_spec_name(paper_dir: Path) -> None:
    out = run([require_tool("nm"), "-g", "--defined-only", str(paper_dir / "build" / "libpaper.a")])
    exported = [line.split()[-1] for line in out.splitlines() if line.strip() and not line.endswith(":")]
    assert exported, "no symbols found"
    assert all(s.startswith("paper_") for s in exported), [s for s in exported if not s.startswith("paper_")]


TWO_SOLVERS_MAIN = r"""
#include <stdio.h>
#include "alpha.h"
#include "beta.h"
int main(void)
{
    const double x[4] = {0.0, 0.0, 0.3, 0.5}, u[2] = {0.1, 0.2};
    double xa[4], Aa[16], Ba[8], xb[4], Ab[16], Bb[8];
    alpha_params pa;
    beta_params pb;
    int na, nb;
    alpha_params_default(&pa);
    beta_params_default(&pb);
    if (alpha_dynamics(x, u, xa, Aa, Ba) || beta_dynamics(x, u, xb, Ab, Bb)) return 1;
    alpha_dims(0, 0, &na, 0, 0);
    beta_dims(0, 0, &nb, 0, 0);
    printf("%d %d %.17g %.17g %g %g\n", na, nb, xa[0], xb[0], pa.d_h, pb.d_h);
    return 0;
}
"""


def test_two_solvers_with_different_names_link_into_one_binary(tmp_path: Path) -> None:
    cc = require_tool("gcc")
    a = make_solver(tmp_path, {"name": "alpha", "horizon": {"N": 10, "T": 1.0}, "humans": {"max": 2}})
    b = make_solver(tmp_path, {"name": "beta", "horizon": {"N": 20, "T": 4.0}, "humans": {"max": 5, "d_h": 0.7}})
    main_c = tmp_path / "main.c"
    main_c.write_text(TWO_SOLVERS_MAIN)
    exe = tmp_path / "two"
    run([cc, *STRICT, "-I", str(a), "-I", str(b), str(main_c), str(a / "build/libalpha.a"),
         str(b / "build/libbeta.a"), "-lm", "-o", str(exe)])
    fields = run([str(exe)]).split()
    assert fields[:2] == ["10", "20"]
    # Same state and control, dt 0.1 vs 0.2: the positions differ as RK4 says.
    assert float(fields[2]) != float(fields[3])
    assert (float(fields[4]), float(fields[5])) == (0.5, 0.7)


def test_generated_folder_builds_on_its_own_with_cmake(paper_dir: Path, tmp_path: Path) -> None:
    cmake = require_tool("cmake")
    build_dir = tmp_path / "cmake-build"
    run([cmake, "-S", str(paper_dir), "-B", str(build_dir), "-DCMAKE_C_FLAGS=-Werror"])
    run([cmake, "--build", str(build_dir)])
    # the package's build/ belongs to its Makefile (make clean deletes it): CMake refuses it
    shadow = tmp_path / "shadow"
    shutil.copytree(paper_dir, shadow, ignore=shutil.ignore_patterns("build"))
    proc = subprocess.run([cmake, "-S", str(shadow), "-B", str(shadow / "build")], capture_output=True, text=True,
                          check=False)
    assert proc.returncode != 0 and "build with -B build-cmake" in proc.stdout + proc.stderr
    assert (build_dir / "libpaper.a").exists() and (build_dir / "libpaper.so").exists()


def test_generated_folder_builds_on_its_own_with_make(paper_dir: Path, tmp_path: Path) -> None:
    run(["make", "-C", str(paper_dir), f"BUILD={tmp_path / 'mk'}", "CC=clang", "CFLAGS=-O1 -Werror"])
    assert (tmp_path / "mk" / "libpaper.so").exists()


def test_header_records_generator_version_and_spec_hash(paper_dir: Path) -> None:
    header = (paper_dir / "paper.h").read_text()
    assert f'#define PAPER_GENERATOR_VERSION "{humanmpc.__version__}"' in header
    assert f'#define PAPER_SPEC_HASH "{Spec.paper().digest()}"' in header


def test_failure_during_generation_leaves_nothing_behind(tmp_path: Path) -> None:
    dest = tmp_path / "deep" / "er" / "solver"

    def explode(tmp: Path) -> None:
        (tmp / "half.c").write_text("int x;")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        write_atomically(dest, explode, force=False)
    assert list(tmp_path.iterdir()) == []


def test_regeneration_requires_force_and_replaces_atomically(tmp_path: Path) -> None:
    dest = tmp_path / "paper"
    generate(Spec(), dest, log=QUIET)
    with pytest.raises(GenerateError, match="--force"):
        generate(Spec(), dest, log=QUIET)
    generate(resolve_spec({"humans": {"max": 3}}), dest, force=True, log=QUIET)
    assert "#define PAPER_NH 3 " in (dest / "paper.h").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper"]


def test_force_never_replaces_a_folder_humanmpc_did_not_write(tmp_path: Path) -> None:
    dest = tmp_path / "mine"
    dest.mkdir()
    (dest / "notes.txt").write_text("precious")
    with pytest.raises(GenerateError, match="not generated by humanmpc"):
        generate(Spec(), dest, force=True, log=QUIET)
    assert (dest / "notes.txt").read_text() == "precious"


def test_build_failure_reports_the_compiler_output(tmp_path: Path) -> None:
    d = make_solver(tmp_path, {"name": "broken", "horizon": {"N": 3}}, built=False)
    (d / "broken.c").write_text((d / "broken.c").read_text() + "\nthis is not C;\n")
    with pytest.raises(BuildError, match="error"):
        build(d, log=QUIET)


def test_load_rebuilds_a_stale_library(tmp_path: Path) -> None:
    d = make_solver(tmp_path, {"name": "stale", "horizon": {"N": 4}})
    lib = d / "build" / "libstale.so"
    old = lib.stat().st_mtime
    os.utime(d / "stale.c")  # touched source: the library is now older than it
    humanmpc.load(d)
    assert lib.stat().st_mtime >= old
    with pytest.raises(humanmpc.LoadError, match="not a generated humanmpc solver"):
        humanmpc.load(tmp_path)


def test_cli_generate_then_build(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "s.yaml"
    spec.write_text("name: cli_robot\nhorizon: {N: 8}\nhumans: {max: 2}\n")
    out = tmp_path / "pkg"
    assert cli.main(["generate", str(spec), "-o", str(out)]) == 0
    assert cli.main(["build", str(out)]) == 0
    assert (out / "build" / "libcli_robot.so").exists()
    assert cli.main(["check", str(spec)]) == 0
    printed = capsys.readouterr().out
    assert "name: cli_robot" in printed and "valid (sha256" in printed
    assert cli.main(["info", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "N=8 intervals" in printed and "cli_robot_dynamics(x, u) -> x_next, A, B" in printed
    # the solver's memory, by part: they add up to the struct (the fallback shares the workspace's union)
    sized = (re.fullmatch(r"\s*(.*?)\s+([\d,]+) B", ln) for ln in printed.splitlines())
    lines = {m.group(1): int(m.group(2).replace(",", "")) for m in sized if m}
    total = lines["cli_robot_solver"]
    top = [v for k, v in lines.items() if k in ("QP data (ocp_qp)", "QP solution = NLP multipliers (ocp_qp_sol)",
                                                "QP warm start (kept iterate)",
                                                "QP workspace (interior point | fallback)", "row screening",
                                                "iterate, parameters, the rest")]
    assert len(top) == 6 and sum(top) == total, lines
    assert lines["fallback (shares the above)"] <= lines["QP workspace (interior point | fallback)"]
    ipm = [v for k, v in lines.items() if k.startswith("interior point: ")]
    assert len(ipm) == 4 and sum(ipm) <= lines["QP workspace (interior point | fallback)"], lines


@pytest.mark.parametrize("command", [[], ["check"], ["generate"], ["build"], ["info"], ["keys"], ["bench"],
                                     ["simulate"], ["evaluate"], ["firmware"], ["firmware-report"], ["demo"]])
def test_every_command_has_help(command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main([*command, "--help"])
    assert info.value.code == 0
    assert "usage: humanmpc-gen" in capsys.readouterr().out


def test_a_native_build_gives_the_same_bits_as_the_portable_default(tmp_path: Path) -> None:
    """Portable by default; --native adds -march=native -funroll-loops for this CPU, IEEE arithmetic kept
    (-ffp-contract=off in both): a closed loop gives bit-identical results either way."""
    import shutil

    import numpy as np

    from humanmpc.codegen.build import NATIVE_FLAGS, PORTABLE_CFLAGS, built_flags, native_supported
    from humanmpc.compare.replay import synthetic_replay

    assert native_supported("gcc")  # gcc on the development machines takes them
    d = make_solver(tmp_path, {"name": "flags", "humans": {"max": 4}}, built=False)
    portable = tmp_path / "portable" / "flags"
    shutil.copytree(d, portable)
    build(d, cc="gcc", native=True, log=QUIET)
    build(portable, cc="gcc", log=QUIET)
    native_flags, portable_flags = built_flags(d), built_flags(portable)
    assert native_flags is not None and portable_flags is not None
    assert f"{PORTABLE_CFLAGS} {NATIVE_FLAGS}" in native_flags
    assert PORTABLE_CFLAGS in portable_flags and "-march" not in portable_flags
    replay = synthetic_replay(resolve_spec({"name": "flags", "humans": {"max": 4}}), 4, 40, seed=5)
    runs = []
    for path in (d, portable):
        solver = humanmpc.load(path)
        solver.set_params(**replay.params)
        runs.append([solver.step(**replay.inputs(t)) for t in range(replay.steps)])
    for a, b in zip(*runs, strict=True):
        assert a.stop_reason == b.stop_reason and a.qp_iterations == b.qp_iterations
        assert np.array_equal(a.x, b.x) and np.array_equal(a.u, b.u)


def test_cli_build_is_portable_by_default_native_on_request_and_info_says_which(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """humanmpc-gen build compiled with -march=native while the package's Makefile used -O2: now both are
    portable unless asked, a change of flags rebuilds, and info reports the flags of the built library."""
    monkeypatch.delenv("CFLAGS", raising=False)
    monkeypatch.delenv("HUMANMPC_NATIVE", raising=False)
    d = make_solver(tmp_path, {"name": "pol", "horizon": {"N": 4}, "humans": {"max": 1}}, built=False)
    assert cli.main(["build", str(d)]) == 0
    assert cli.main(["info", str(d)]) == 0
    out = capsys.readouterr()
    assert "portable" in out.err and "-march=native" not in out.err
    line = next(ln for ln in out.out.splitlines() if ln.strip().startswith("built with"))
    assert "-O2 -ffp-contract=off" in line and "-march=native" not in line and "(portable" in line
    portable_lib = (d / "build" / "libpol.so").read_bytes()
    assert cli.main(["build", str(d), "--native"]) == 0
    assert cli.main(["info", str(d)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.strip().startswith("built with"))
    assert "-march=native -funroll-loops" in line and "may not run on another" in line
    assert (d / "build" / "libpol.so").read_bytes() != portable_lib  # the new flags rebuilt it
    # the Makefile alone: the same policy (make -n prints the compile commands)
    run(["make", "-C", str(d), "clean"])
    plain = run(["make", "-n", "-C", str(d), "--no-print-directory"])
    native = run(["make", "-n", "-C", str(d), "--no-print-directory", "NATIVE=1"])
    assert "-O2 -ffp-contract=off" in plain and "-march=native" not in plain
    assert "-O2 -ffp-contract=off -march=native -funroll-loops" in native


def test_cmake_follows_the_same_flag_policy(paper_dir: Path, tmp_path: Path) -> None:
    cmake = require_tool("cmake")
    for native in ("OFF", "ON"):
        build_dir = tmp_path / f"cmake-{native}"
        run([cmake, "-S", str(paper_dir), "-B", str(build_dir), "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON",
             f"-DHUMANMPC_NATIVE={native}"])
        commands = (build_dir / "compile_commands.json").read_text()
        assert "-O2" in commands and "-O3" not in commands and "-ffp-contract=off" in commands
        assert ("-march=native" in commands) == (native == "ON")
