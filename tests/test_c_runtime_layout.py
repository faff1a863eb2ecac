"""The layout of the hand-written C runtime (c_runtime/): one object per file pair, one translation unit.

Every runtime .c is compiled once, by the solver's translation unit, which includes them in a fixed
order; no .c includes another. Headers only include headers of their own layer or of a layer below
(the QP layer below the NLP layer's common header, that below the monitor, that below the rest of the
NLP layer), so that a lower layer never needs an upper one. Each file opens with a comment naming it.
The test programs that compile the QP layer alone take the list of tests/c/qp_runtime.h, which must
follow the translation unit's.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.conftest import make_solver

REPO = Path(__file__).resolve().parents[1]
RUNTIME = REPO / "c_runtime"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def runtime_files(suffix: str) -> list[Path]:
    return sorted(RUNTIME.glob(f"*{suffix}"))


def layer(name: str) -> int:
    """0 shared, 1 QP, 2 the NLP layer's common header and types, 3 the monitor, 4 the rest of the NLP,
    5 the controller around the solver.
    hm_types.h, the umbrella of the QP layer's types (the public header includes it), is the QP layer's."""
    if name == "hm_types.h":
        return 1
    if name.startswith("hm_"):
        return 0
    if name.startswith("ocp_qp"):
        return 1
    if name in ("ocp_nlp_common.h", "ocp_nlp_common.c", "ocp_nlp_types.h"):
        return 2
    if name.startswith("monitor"):
        return 3
    if name.startswith("controller"):
        return 5
    assert name.startswith("ocp_nlp_"), name
    return 4


@pytest.fixture(scope="module")
def tu_sources(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """The runtime .c files that a generated solver's translation unit includes, in order."""
    d = make_solver(tmp_path_factory.mktemp("layout"), {"name": "layout"}, built=False)
    text = (d / "layout.c").read_text()
    return [f.removeprefix("runtime/") for f in INCLUDE.findall(text) if f.endswith(".c")]


def test_every_runtime_source_is_in_the_translation_unit_once(tu_sources: list[str]) -> None:
    assert sorted(tu_sources) == sorted(p.name for p in runtime_files(".c"))
    assert len(set(tu_sources)) == len(tu_sources)


def test_translation_unit_goes_up_the_layers(tu_sources: list[str]) -> None:
    layers = [layer(f) for f in tu_sources]
    assert layers == sorted(layers), tu_sources


def test_no_runtime_file_includes_a_source_file() -> None:
    for p in runtime_files(".c") + runtime_files(".h"):
        included = INCLUDE.findall(p.read_text())
        assert not [f for f in included if f.endswith(".c")], p.name


def test_headers_include_only_their_layer_or_below() -> None:
    for p in runtime_files(".h"):
        for f in INCLUDE.findall(p.read_text()):
            assert (RUNTIME / f).is_file(), (p.name, f)
            assert layer(f) <= layer(p.name), f"{p.name} (layer {layer(p.name)}) includes {f} (layer {layer(f)})"


def test_monitor_does_not_need_the_sqp() -> None:
    text = (RUNTIME / "monitor.h").read_text() + (RUNTIME / "monitor.c").read_text()
    assert not [f for f in INCLUDE.findall(text) if f not in ("hm_common.h", "monitor.h", "ocp_nlp_common.h")]


def test_each_file_opens_with_a_comment_naming_it() -> None:
    for p in runtime_files(".c") + runtime_files(".h"):
        assert p.read_text().startswith(f"/*\n * {p.name}: "), p.name


def test_qp_test_programs_include_the_qp_layer_in_translation_unit_order(tu_sources: list[str]) -> None:
    listed = INCLUDE.findall((REPO / "tests" / "c" / "qp_runtime.h").read_text())
    assert listed == [f for f in tu_sources if f.startswith("ocp_qp")]
