"""Deep expressions (issue 10): long sums work end to end, deeper nesting than
``ir.expr.MAX_DEPTH`` is a located error, and neither overflows Python's stack."""

from __future__ import annotations

import csv
import math
import sys
import threading
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.errors import ErrorGroup, SpringcError, render_all
from springc.ir import expr
from springc.parse import parse_text

HELP = ("help: split it with intermediate variables (`Real s1 = a1 + a2 + ...;`); "
        "docs/language.md, \"Limits\", says how depth is counted")


def run(tmp_path: Path, *args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args), prog_name="springc", catch_exceptions=False,
                                env={"SPRINGC_PATH": "", "SPRINGC_CACHE_DIR": str(tmp_path)})
    return result.exit_code, result.stdout, result.stderr


def model(equation: str, declarations: str = "") -> str:
    return (f"model M\n  Real x(start = 1);\n  Real y(start = 0);\n{declarations}"
            f"equation\n  {equation};\n  der(x) = -(" + " + ".join(["x"] * 2000) + ") / 2000;\n"
            "end M;\n")


def test_sum_of_2000_terms_simulates_to_the_closed_form(tmp_path: Path) -> None:
    # der(y) = time + ... + time (2,000 terms) gives y = 1000 t^2; der(x) = -x, x = e^-t.
    source = tmp_path / "sum.mdl"
    source.write_text(model("der(y) = " + " + ".join(["time"] * 2000)))
    out = tmp_path / "out.csv"
    code, _, err = run(tmp_path, "simulate", str(source), "--stop", "1", "--interval", "0.25",
                       "--rtol", "1e-10", "-o", str(out))
    assert code == 0, err
    rows = list(csv.DictReader(out.open()))
    assert [float(r["time"]) for r in rows] == [0.0, 0.25, 0.5, 0.75, 1.0]
    for row in rows:
        t = float(row["time"])
        assert float(row["y"]) == pytest.approx(1000 * t * t, rel=1e-8, abs=1e-9)
        assert float(row["x"]) == pytest.approx(math.exp(-t), rel=1e-7)


def test_nesting_of_100000_is_a_located_error(tmp_path: Path) -> None:
    source = tmp_path / "deep.mdl"
    source.write_text(model("y = " + "-(" * 100_000 + "x" + ")" * 100_000))
    code, out, err = run(tmp_path, "check", str(source))
    lines = err.splitlines()
    assert (code, out) == (1, "")
    assert lines[0] == (f"{source}:5:7: error: expression nested too deeply "
                        "(depth 100000, limit 3000)")
    assert lines[-1] == HELP


def test_a_run_of_100000_minus_signs_is_a_located_error(tmp_path: Path) -> None:
    source = tmp_path / "minus.mdl"
    source.write_text(model("y = " + "- " * 100_000 + "x"))
    code, _, err = run(tmp_path, "flatten", str(source))
    assert code == 1
    assert err.splitlines()[0] == (f"{source}:5:7: error: expression nested too deeply "
                                   "(depth 100000, limit 3000)")


def errors(text: str) -> str:
    with pytest.raises((SpringcError, ErrorGroup)) as info:
        parse_text(text, "t.mo")
    return render_all(info.value, lambda _: text)


def test_the_limit_is_exact_and_counts_operators() -> None:
    # A sum of n terms is n - 1 levels deep; MAX_DEPTH levels pass, one more does not.
    def text(terms: int) -> str:
        return "model M\n  Real y = " + " + ".join(["1"] * terms) + ";\nend M;\n"

    assert expr.MAX_DEPTH == 3000
    parse_text(text(3001), "t.mo")
    assert errors(text(3002)).splitlines()[0] == (
        "t.mo:2:12: error: expression nested too deeply (depth 3001, limit 3000)")
    nested = "model M\n  Real y = " + "sin(" * 3000 + "1" + ")" * 3000 + ";\nend M;\n"
    parse_text(nested, "t.mo")
    assert "(depth 3001, limit 3000)" in errors(nested.replace("sin(1)", "sin(-1)"))


def test_classes_nested_too_deeply_are_located() -> None:
    text = "".join(f"package P{i}\n" for i in range(800)) + "".join(
        f"end P{i};\n" for i in reversed(range(800)))
    lines = errors(text).splitlines()
    assert lines[0].startswith("t.mo:")
    assert lines[0].endswith(": error: definitions and equations nested too deeply "
                             "(depth 3001, limit 3000)")
    assert lines[-1] == ("help: nest classes, equations and modifications less; "
                         "docs/language.md, \"Limits\", says how depth is counted")


def test_a_run_of_stray_unary_operators_is_one_error() -> None:
    text = "model M\n  Real y = 2 * " + "- " * 2000 + "1;\nend M;\n"
    assert errors(text) == (
        "t.mo:2:16: error: unexpected '-'\n"
        f"    2 | {text.splitlines()[1][:160]}...\n"  # the 160 columns around the caret
        "      |                ^\n"
        "help: a unary '-' may only start an expression or an operand of a comparison; "
        "put it in parentheses, e.g. a * (-b)")


def test_recursion_limit_follows_the_thread_stack() -> None:
    seen: list[int] = []
    previous = threading.stack_size(4 << 20)
    try:
        thread = threading.Thread(target=lambda: seen.append(expr.recursion_limit()))
        thread.start()
        thread.join()
    finally:
        threading.stack_size(previous)
    assert seen == [max(sys.getrecursionlimit(), (4 << 20) // 512)]


def test_recursion_room_raises_and_restores_the_limit() -> None:
    before = sys.getrecursionlimit()
    with expr.recursion_room():
        inside = sys.getrecursionlimit()
    assert inside == expr.recursion_limit() >= before
    assert sys.getrecursionlimit() == before


def test_the_recursion_room_is_shared_by_nested_runs_and_threads() -> None:
    before = sys.getrecursionlimit()
    main_room = max(before, expr.recursion_limit())
    seen: dict[str, int] = {}
    entered, release = threading.Event(), threading.Event()

    def small_stack_run() -> None:
        with expr.recursion_room():
            seen["thread"] = sys.getrecursionlimit()
            entered.set()
            release.wait(timeout=60)

    with expr.recursion_room():
        with expr.recursion_room():  # nested: the same limit
            seen["nested"] = sys.getrecursionlimit()
        seen["outer"] = sys.getrecursionlimit()
        previous = threading.stack_size(1 << 20)
        try:
            thread = threading.Thread(target=small_stack_run)
            thread.start()
        finally:
            threading.stack_size(previous)
        entered.wait(timeout=60)
        seen["while the thread runs"] = sys.getrecursionlimit()
        release.set()
        thread.join()
        seen["after the thread"] = sys.getrecursionlimit()
    small = max(before, (1 << 20) // 512)  # 2,048 calls on a 1 MiB stack
    assert seen == {"nested": main_room, "outer": main_room, "thread": small,
                    "while the thread runs": small, "after the thread": main_room}
    assert sys.getrecursionlimit() == before
