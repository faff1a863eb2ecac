"""Names a package derives from its spec's name: two valid names never share a file, symbol, macro or target,
and no name shadows a C header or takes a prefix C reserves."""

from __future__ import annotations

import itertools
import re
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from humanmpc.codegen.names import clash, derived_names, suffixes
from humanmpc.codegen.ros import write_ros
from humanmpc.codegen.spec import SpecError, parse_spec_text

from .conftest import make_solver, require_tool


def is_valid(name: str) -> bool:
    try:
        parse_spec_text(f"name: {name}")
    except SpecError:
        return False
    return True


# Words names are made of, chosen to hit the suffix table: its words, their starts and ends, and others.
WORDS = ["lk", "a", "nav", "_model", "_controller", "_solver", "_qp", "_status", "_stop", "_params", "_cost",
         "_dynamics", "_n", "_h", "_hpp", "_shared", "_ros", "_node", "_x", "_", "_m", "_casadi", "_input",
         "_message", "_rows", "_ocp", "_ipm", "_model_dynamics", "_hessian", "_gn", "_work", "_in", "_out",
         "_collision"]
NAMES = sorted({"".join(p) for k in (1, 2, 3) for p in itertools.product(WORDS, repeat=k)
                if not p[0].startswith("_")})


def test_any_two_valid_names_built_from_the_tables_words_derive_disjoint_names() -> None:
    """Exhaustive over names of up to three words: every pair of valid names is disjoint (in lower case, so
    macros and case-insensitive file systems are covered), and clash() refuses exactly what collides."""
    valid = [n for n in NAMES if clash(n) is None]
    seen: dict[str, str] = {}
    for name in valid:
        for derived in derived_names(name):
            assert derived not in seen, f"{seen.get(derived)!r} and {name!r} both define {derived!r}"
            seen[derived] = name
    refused = [n for n in NAMES if clash(n) is not None]
    assert "lk_model" in refused and "lk" in valid and len(valid) > 100 and len(refused) > 100
    for name in refused:  # each refusal names a real collision
        c = clash(name)
        assert c is not None and c.other + c.other_suffix == name.lower() + c.suffix
        assert c.other_suffix in suffixes() and c.suffix in suffixes()


@settings(max_examples=500, deadline=None, derandomize=True)
@given(a=st.text("abdehlnopqruvwxyz_0", min_size=0, max_size=10), s=st.sampled_from(sorted(suffixes())),
       cut=st.integers(1, 40), b=st.text("abdehlnopqruvwxyz_0", min_size=0, max_size=14))
def test_a_name_that_extends_another_by_the_start_of_a_generated_suffix_is_refused_if_they_collide(
        a: str, s: str, cut: int, b: str) -> None:
    """Property over the suffix table: the longer of two colliding names is always refused (with a name
    ``a + start of a suffix``, the only way to collide), and two names that pass never collide."""
    a = "q" + a
    longer = a + s[:cut]
    if longer != a and derived_names(a) & derived_names(longer):
        assert clash(longer) is not None, f"{a!r} and {longer!r} collide but {longer!r} is accepted"
    other = "q" + b
    if other != a and clash(a) is None and clash(other) is None:
        assert not derived_names(a) & derived_names(other), (a, other)


@pytest.mark.parametrize(("name", "why"), [
    ("lk_model", "a package named 'lk' defines"),
    ("nav_controller", "does not end in '_controller'"),
    ("nav_qp", "does not end in '_qp'"),
    ("nav_shared", "does not end in '_shared'"),
    ("nav_ros", "does not end in '_ros'"),
    ("printf", "would shadow the system header <printf.h>"),
    ("stdio", "would shadow the system header <stdio.h>"),
    ("pthread", "would shadow the system header <pthread.h>"),
    ("strange", "<string.h>'s and <stdlib.h>'s future functions"),
    ("isle", "<ctype.h>'s future functions"),
    ("hm_nav", "the runtime's and CasADi's own prefixes"),
    ("Nav", "has capital letters"),
])
def test_a_name_that_could_collide_or_shadow_is_refused_saying_which_and_why(name: str, why: str) -> None:
    with pytest.raises(SpecError) as info:
        parse_spec_text(f"name: {name}")
    assert info.value.problems[0].startswith(f"name: {name!r}") and why in info.value.problems[0]


def test_the_table_covers_every_name_a_generated_package_defines(paper_dir: Path, tmp_path: Path) -> None:
    """Files, nm's external symbols, the identifiers the headers declare, CMake and ROS targets: each is
    the name followed by a suffix of the table, so the proofs above hold for what is really generated."""
    table = suffixes()

    def suffix_of(derived: str) -> str:
        assert derived.lower().startswith("paper"), derived
        return derived.lower()[len("paper"):]

    top = [p.name for p in paper_dir.iterdir() if p.is_file()]
    files = [f for f in top if f not in ("Makefile", "CMakeLists.txt", "manifest.json", "spec.yaml")]
    out = subprocess.run([require_tool("nm"), "-g", "--defined-only", str(paper_dir / "build" / "libpaper.a")],
                         capture_output=True, text=True, check=True).stdout
    symbols = [line.split()[-1] for line in out.splitlines() if len(line.split()) == 3]
    headers = "".join((paper_dir / f).read_text() for f in files if f.endswith((".h", ".hpp")))
    identifiers = set(re.findall(r"\b(?:paper|PAPER)\w*", headers))
    for header in ("paper.h", "paper_model.h"):  # and what its macros declare (the runtime's types, HM_NS)
        cpp = [require_tool("gcc"), "-E", "-dD", "-P", "-I", str(paper_dir), str(paper_dir / header)]
        expanded = subprocess.run(cpp, capture_output=True, text=True, check=True).stdout
        identifiers |= set(re.findall(r"\b(?:paper|PAPER)\w*", expanded))
    cmake = (paper_dir / "CMakeLists.txt").read_text()
    targets = set(re.findall(r"add_library\((\w+)", cmake))
    ros = write_ros(paper_dir, tmp_path / "paper_ros_src")
    ros_cmake = (ros / "paper_ros" / "CMakeLists.txt").read_text()
    targets |= set(re.findall(r"(?:add_library|add_executable|project)\((\w+)", ros_cmake))
    ros_files = {p.name for p in (ros / "paper_ros").rglob("*") if p.name.startswith("paper")}
    everything = [*files, *symbols, *identifiers, *targets, *ros_files, "paper_ros", "libpaper.a", "libpaper.so"]
    missing = sorted({d for d in everything if suffix_of(d.removeprefix("lib")) not in table})
    assert not missing, f"generated names outside codegen/names.py's table: {missing}"
    assert len(symbols) > 100 and len(identifiers) > 100


PREFIX_PAIR_MAIN = r"""
#include <stdio.h>
#include "lk.h"
#include "lk_nav.h"
int main(void)
{
    lk_params pa;
    lk_nav_params pb;
    lk_params_default(&pa);
    lk_nav_params_default(&pb);
    printf("%d %d %g %g\n", LK_N, LK_NAV_N, pa.d_h, pb.d_h);
    return 0;
}
"""


def test_two_packages_whose_names_share_a_prefix_link_into_one_program_without_a_shared_symbol(
        tmp_path: Path) -> None:
    """lk and lk_model had 7 symbols and lk_model.h/.c in common: lk_model is now refused, and lk with a name
    that extends it and is accepted (lk_nav) share no file, no external symbol, and build into one program."""
    with pytest.raises(SpecError, match="a package named 'lk' defines"):
        parse_spec_text("name: lk_model")
    cc = require_tool("gcc")
    a = make_solver(tmp_path, {"name": "lk", "horizon": {"N": 5, "T": 0.5}, "humans": {"max": 1}})
    b = make_solver(tmp_path, {"name": "lk_nav", "horizon": {"N": 6, "T": 0.6}, "humans": {"max": 1}})
    assert not {p.name for p in a.iterdir() if p.is_file() and p.name.startswith("lk")} & {
        p.name for p in b.iterdir() if p.is_file() and p.name.startswith("lk")}
    nm = require_tool("nm")
    defined = []
    for lib in (a / "build/liblk.a", b / "build/liblk_nav.a"):
        out = subprocess.run([nm, "-g", "--defined-only", str(lib)], capture_output=True, text=True, check=True).stdout
        defined.append({line.split()[-1] for line in out.splitlines() if len(line.split()) == 3})
    assert defined[0] and defined[1] and not defined[0] & defined[1]
    main_c = tmp_path / "main.c"
    main_c.write_text(PREFIX_PAIR_MAIN)
    exe = tmp_path / "pair"
    subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-I", str(a), "-I", str(b),
                    str(main_c), str(a / "build/liblk.a"), str(b / "build/liblk_nav.a"), "-lm", "-o", str(exe)],
                   check=True, capture_output=True, text=True)
    assert subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split()[:2] == ["5", "6"]


@pytest.mark.parametrize("name", ["paper", "mpc_paper", "exact_rti", "paper_float", "fw_h10_float", "mpc_w1_q2",
                                  "bi_nh5", "crowd30", "alpha", "beta", "mine", "fuzz", "cli_robot", "robot_a"])
def test_the_names_the_project_uses_stay_valid(name: str) -> None:
    assert is_valid(name)
