"""The spec: paper defaults, every malformed spec rejected with the key named, nothing written."""

from __future__ import annotations

import math
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from humanmpc import cli
from humanmpc.codegen.render import c_identifier
from humanmpc.codegen.spec import Spec, SpecError, describe_schema, load_spec, parse_spec_text, resolve_spec


def test_preset_paper_gives_the_papers_values_and_the_defaults_are_the_evaluations() -> None:
    """The paper's values, copied by hand from its Table I and Sec. IV; the defaults, those chosen on the
    evaluation's tuning seeds (docs/evaluation.md)."""
    p = parse_spec_text("preset: paper")
    assert p == Spec.paper() and p.name == "paper"
    assert (p.horizon.T, p.horizon.N) == (5.0, 50) and math.isclose(p.dt, 0.1)
    assert p.weights.goal == (0.5, 0.5, 0.0, 250.0) and p.weights.goal_terminal == (40.0, 40.0, 2.0, 0.0)
    assert p.weights.control == (0.0, 0.0) and Spec().weights.control == (0.0, 2.0)
    assert (p.collision_cost.q, p.collision_cost.d_th, p.collision_cost.kappa) == (2.0, 1.0, 5.0)
    assert (p.humans.d_h, p.obstacle.d_s, p.obstacle.slack_l1) == (0.5, 0.5, 100.0)
    assert p.solver.hessian == "gauss_newton"
    assert p.controller.approach is False and p.controller.recovery_iterations == 0 and p.controller.loop_ratio == 0.0
    d = Spec()
    assert d.weights.goal == (0.5, 0.5, 0.0, 50.0) and d.collision_cost.q == 50.0 and d.obstacle.slack_l1 == 1000.0
    assert d.solver.hessian == "exact" and d.controller.approach is True and d.controller.recovery_iterations == 10
    assert parse_spec_text("preset: paper\ncollision_cost: {q: 7.0}").collision_cost.q == 7.0  # the spec wins


def test_a_larger_n_h_raises_the_default_track_capacity_and_a_smaller_given_one_is_refused() -> None:
    assert Spec().controller.max_tracks == 32
    assert parse_spec_text("humans: {max: 40}").controller.max_tracks == 40
    with pytest.raises(SpecError, match=r"controller\.max_tracks: 10 is below humans\.max \(40\)"):
        parse_spec_text("humans: {max: 40}\ncontroller: {max_tracks: 10}")


def test_empty_file_and_empty_mapping_give_the_defaults() -> None:
    assert parse_spec_text("") == Spec()
    assert parse_spec_text("{}") == Spec()


def test_partial_spec_keeps_other_defaults() -> None:
    s = parse_spec_text("humans: {max: 30}\nhorizon: {N: 20}\n")
    assert s.humans.max == 30 and s.humans.d_h == 0.5
    assert s.horizon.N == 20 and s.horizon.T == 5.0


def test_exponent_notation_without_dot_is_a_number() -> None:
    assert parse_spec_text("solver: {qp_tol: 1e-8}").solver.qp_tol == 1e-8


def test_resolved_spec_round_trips_through_yaml() -> None:
    s = parse_spec_text("name: robot_a\nhumans: {max: 3}\nweights: {control: [0.1, 0.2]}")
    again = parse_spec_text(s.to_yaml())
    assert again == s and again.digest() == s.digest()


def test_digest_changes_with_any_value() -> None:
    assert Spec().digest() != parse_spec_text("obstacle: {d_s: 0.6}").digest()


def test_every_key_is_documented_with_its_default() -> None:
    rows = describe_schema()
    keys = {k for k, _, _ in rows}
    assert {"name", "horizon.T", "humans.max", "weights.goal", "monitor.deadline_ms"} <= keys
    assert all(doc for _, doc, _ in rows)


# (spec text, key path that the error must name, a fragment of the rule)
MALFORMED = [
    ("horizon: {n: 50}", "horizon.n", "did you mean 'N'"),
    ("wieghts: {}", "wieghts", "did you mean 'weights'"),
    ("horizon: {N: 0}", "horizon.N", ">= 1"),
    ("horizon: {N: -3}", "horizon.N", ">= 1"),
    ("horizon: {N: 50.5}", "horizon.N", "integer"),
    ("horizon: {N: true}", "horizon.N", "integer"),
    ("horizon: {T: 0}", "horizon.T", "> 0"),
    ("horizon: {T: .nan}", "horizon.T", "finite"),
    ("horizon: {T: .inf}", "horizon.T", "finite"),
    ("horizon: {T: '5.0'}", "horizon.T", "number"),
    ("horizon: 5", "horizon", "mapping"),
    ("weights: {goal: [1, 2, -3, 4]}", "weights.goal[2]", "0 <= w <= 1e+09"),
    ("weights: {goal: [1, 2, 3]}", "weights.goal", "exactly 4"),
    ("weights: {control: 1.0}", "weights.control", "list"),
    ("weights: {goal_terminal: [1, 2, .nan, 4]}", "weights.goal_terminal[2]", "finite"),
    ("name: 'x; system(\"rm -rf /\")'", "name", "C identifier"),
    ("name: 'paper */ int evil; /*'", "name", "C identifier"),
    ("name: '3d'", "name", "C identifier"),
    ("name: 'int'", "name", "reserved"),
    ("name: 'while'", "name", "reserved"),
    ("name: 'hm'", "name", "reserved"),
    ("name: 'time'", "name", "would shadow the system header <time.h>"),
    ("name: 'math'", "name", "would shadow the system header <math.h>"),
    ("name: 'Stddef'", "name", "would shadow the system header <stddef.h>"),
    ("name: 42", "name", "string"),
    ("name: " + "a" * 40, "name", "too long"),
    ("bounds: {v: [1.0, 0.0]}", "bounds.v", "lower bound must be < upper"),
    ("bounds: {a: [1.0, 1.0]}", "bounds.a", "lower bound must be < upper"),
    ("bounds: {omega: [0.5]}", "bounds.omega", "interval"),
    ("bounds: {v: [0.2, 1.0]}", "bounds.v", "standstill"),
    ("collision_cost: {kappa: 0}", "collision_cost.kappa", "0 < kappa"),
    ("collision_cost: {q: -2}", "collision_cost.q", "0 <= q"),
    ("humans: {d_h: -0.1}", "humans.d_h", "0 <= d_h"),
    ("humans: {max: -1}", "humans.max", ">= 0"),
    ("humans: {max: 100000}", "humans.max", "<= 200"),
    ("obstacle: {slack_l1: -1}", "obstacle.slack_l1", "0 <= slack_l1"),
    ("integrator: {method: euler}", "integrator.method", "one of rk4"),
    ("integrator: {steps: 0}", "integrator.steps", ">= 1"),
    ("solver: {qp_tol: 0}", "solver.qp_tol", "0 < qp_tol"),
    ("solver: {hessian: newton}", "solver.hessian", "one of gauss_newton, exact"),
    ("solver: {hessian: true}", "solver.hessian", "one of gauss_newton, exact"),
    ("monitor: {deadline_ms: -5}", "monitor.deadline_ms", "0 < deadline_ms"),
    ("name: a\nname: b", "name", "duplicate key"),
    ("[1, 2, 3]", "spec", "mapping"),
    ("horizon: {N: [50", "", "not valid YAML"),
]


@pytest.mark.parametrize(("text", "key", "rule"), MALFORMED, ids=[m[1] or "yaml" for m in MALFORMED])
def test_malformed_spec_is_rejected_naming_key_and_rule(text: str, key: str, rule: str) -> None:
    with pytest.raises(SpecError) as info:
        parse_spec_text(text)
    message = str(info.value)
    assert rule in message
    if key:
        assert any(p.startswith(f"{key}:") for p in info.value.problems), message


@pytest.mark.parametrize(("text", "key", "rule"), MALFORMED, ids=[m[1] or "yaml" for m in MALFORMED])
def test_generate_with_malformed_spec_fails_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, key: str, rule: str
) -> None:
    spec_file = tmp_path / "bad.yaml"
    spec_file.write_text(text)
    out = tmp_path / "out" / "solver"
    assert cli.main(["generate", str(spec_file), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert rule in err and (not key or key in err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.yaml"]


def test_all_problems_are_reported_at_once() -> None:
    with pytest.raises(SpecError) as info:
        parse_spec_text("horizon: {N: 0, T: -1}\nweights: {goal: [1, -1, 1, 1]}\nnam: x")
    assert len(info.value.problems) == 4


def test_spec_built_in_code_is_validated_again_before_generation(tmp_path: Path) -> None:
    from humanmpc.codegen.generate import generate

    bad = Spec(name='x"; int y; /*')
    with pytest.raises(SpecError, match="C identifier"):
        generate(bad, tmp_path / "x")
    assert list(tmp_path.iterdir()) == []


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    n=st.integers(1, 200),
    nh=st.integers(0, 40),
    t=st.floats(0.1, 30.0),
    w=st.lists(st.floats(0.0, 1e3), min_size=4, max_size=4),
    lo=st.floats(-3.0, -0.1),  # a protective stop must be able to brake: the lower bound is <= -0.1
    width=st.floats(0.1, 5.0),  # the upper bound too: a reversing robot brakes at it
)
def test_valid_specs_resolve_to_what_was_written(n: int, nh: int, t: float, w: list[float], lo: float,
                                                 width: float) -> None:
    data = {"horizon": {"N": n, "T": t}, "humans": {"max": nh}, "weights": {"goal": w},
            "bounds": {"a": [lo, width]}}
    s = resolve_spec(yaml.safe_load(yaml.safe_dump(data)))
    assert (s.horizon.N, s.horizon.T, s.humans.max) == (n, t, nh)
    assert s.weights.goal == tuple(w)
    assert s.n_rows == nh + 1


def test_yaml_aliases_are_refused_before_they_expand(tmp_path: Path) -> None:
    """Nested aliases expand exponentially (a 510-byte document to gigabytes): a spec may use none."""
    lines = ["a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"{c}: &{c} [{', '.join([f'*{p}'] * 9)}]" for p, c in zip("abcdefgh", "bcdefghi", strict=True)]
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("\n".join(lines) + "\n")
    assert len(bomb.read_bytes()) < 600
    with pytest.raises(SpecError, match="line 2: YAML aliases"):
        load_spec(bomb)
    with pytest.raises(SpecError, match="at most"):
        parse_spec_text("name: x\n" + "# padding\n" * 10000)


def test_an_empty_spec_file_is_an_error_not_the_default_spec(tmp_path: Path) -> None:
    for text in ("", "\n", "# only a comment\n"):
        f = tmp_path / "empty.yaml"
        f.write_text(text)
        with pytest.raises(SpecError, match="holds no keys"):
            load_spec(f)


def test_a_name_with_a_trailing_newline_is_not_a_c_identifier() -> None:
    with pytest.raises(SpecError, match="not a C identifier"):
        parse_spec_text('name: "paper\\n"')
    with pytest.raises(ValueError, match="not a C identifier"):
        c_identifier("paper\n")


def test_a_number_too_large_for_a_double_is_an_error_not_a_traceback(tmp_path: Path) -> None:
    for text, key in ((f"humans: {{d_h: {10**400}}}", "humans.d_h"), (f"horizon: {{T: {10**400}}}", "horizon.T"),
                      (f"weights: {{goal: [1, {10**400}, 0, 1]}}", "weights.goal[1]")):
        with pytest.raises(SpecError, match=re.escape(key) + r".* is too large"):
            parse_spec_text(text)


@pytest.mark.parametrize(("text", "line", "words"), [
    ("name: a\nhorizon\n  N: 5\nsolver:\n  x: 1\n", 2, "'horizon' is a key without ':'"),
    ("name: a\nbounds: {v: [0, 1]\nsolver: 3\n", 2, "is not closed"),
    ("name: \"abc\nx: 1\n", 1, "quoted string opened on this line is not closed"),
    ("horizon:\n\tN: 50\n", 2, "tab character: indent with spaces"),
    ("horizon:\n    N: 5\n  T: 3\n", 3, "'T: 3' does not fit the indentation"),
    ("name: a: b\n", 1, "quote a value"),
    ("name: a\nx: \x01\n", 2, "U+0001 is not allowed in YAML"),
    ("name: a\n---\nname: b\n", 2, "a spec is one document"),
])
def test_a_yaml_syntax_error_names_the_file_and_the_line_of_the_mistake(tmp_path: Path, text: str, line: int,
                                                                        words: str) -> None:
    """PyYAML marks the line after a key without ':' or an unclosed bracket or quote, in its own words;
    the message names the file, the line where the mistake is, and what to write instead."""
    f = tmp_path / "typo.yaml"
    f.write_text(text)
    with pytest.raises(SpecError) as info:
        load_spec(f)
    assert str(info.value).startswith(f"invalid {f}:")
    assert info.value.problems[0].startswith((f"line {line}: ", f"line {line}, ")), info.value.problems
    assert words in info.value.problems[0]
    assert "while scanning" not in str(info.value) and "while parsing" not in str(info.value)


def _check_in_a_child(path: str) -> subprocess.CompletedProcess[str]:
    """humanmpc-gen check PATH in a process with 1 GB of address space and 60 s: reading /dev/zero
    whole grew to 6.9 GB, /dev/urandom and a FIFO without a writer hung."""
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    return subprocess.run([sys.executable, "-m", "humanmpc.codegen", "check", path], capture_output=True, text=True,
                          timeout=60, preexec_fn=limit, check=False)


@pytest.mark.parametrize(("path", "kind"), [("/dev/zero", "a character device"),
                                            ("/dev/urandom", "a character device"),
                                            ("{tmp}", "a folder"), ("{tmp}/fifo", "a pipe (FIFO)")])
def test_a_spec_path_that_is_not_a_regular_file_is_refused_without_reading_it(tmp_path: Path, path: str,
                                                                              kind: str) -> None:
    os.mkfifo(tmp_path / "fifo")
    path = path.format(tmp=tmp_path)
    t0 = time.monotonic()
    proc = _check_in_a_child(path)
    assert proc.returncode == 2, proc.stderr
    assert f"{path} is {kind}, not a spec file" in proc.stderr and "Traceback" not in proc.stderr
    assert time.monotonic() - t0 < 30


def test_a_huge_spec_file_is_refused_after_reading_a_bounded_prefix(tmp_path: Path) -> None:
    """A sparse 8 GB file: the size is not trusted (files under /proc say 0), the read is bounded."""
    big = tmp_path / "big.yaml"
    with big.open("wb") as f:
        f.truncate(8 << 30)
    proc = _check_in_a_child(str(big))
    assert proc.returncode == 2 and f"{big} is larger than 65,536 bytes" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize("opening", ["[", "{a: ", "- "])
def test_deeply_nested_lists_or_maps_are_refused_naming_the_file(tmp_path: Path, opening: str) -> None:
    """400 nested lists or maps in a 1 KB spec raised RecursionError in PyYAML's composer."""
    closing = {"[": "]", "{a: ": "}", "- ": ""}[opening]
    f = tmp_path / "deep.yaml"
    f.write_text("name: deep\nweights:\n  " + opening * 400 + "1" + closing * 400 + "\n")
    assert f.stat().st_size < 2100
    proc = _check_in_a_child(str(f))
    assert proc.returncode == 2, proc.stderr
    assert f"invalid {f}" in proc.stderr and "nested more than 16 deep" in proc.stderr
    assert "Traceback" not in proc.stderr and "RecursionError" not in proc.stderr
