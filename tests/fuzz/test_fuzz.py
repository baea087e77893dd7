"""Grammar-aware fuzzing of ``springc check`` and ``springc flatten`` (issue 10).

Inputs are the bundled models (``models/*.mdl``) and snippets generated from the
grammar's constructs, mutated token by token (deleted, duplicated, swapped, replaced by
hostile identifiers and numbers such as ``1e309``, ``nan``, deep nesting, huge array
sizes). Every run must end with exit code 0, 1 or 2 and print no traceback.

CI runs a fixed, derandomized set (``SPRINGC_FUZZ_EXAMPLES``, default 400, about 40 s);
a longer run for developers:
``SPRINGC_FUZZ_EXAMPLES=5000 SPRINGC_FUZZ_RANDOM=1 python -m pytest tests/fuzz``
(see tests/fuzz/README.md).
"""

from __future__ import annotations

import os
import re
import resource
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from springc.cli import main

ROOT = Path(__file__).resolve().parents[2]
MODELS = {p.name: p.read_text() for p in sorted((ROOT / "models").glob("*.mdl"))}
EXAMPLES = int(os.environ.get("SPRINGC_FUZZ_EXAMPLES", "400"))
RANDOM = os.environ.get("SPRINGC_FUZZ_RANDOM") == "1"  # new inputs on every run
SECONDS_PER_RUN = 20  # a run past this is a hang (a finding), not a slow pass

TOKEN = re.compile(r"'(?:[^'\\\n]|\\.)*'|\"(?:[^\"\\]|\\.)*\"|[A-Za-z_][A-Za-z0-9_]*"
                   r"|[0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?|\.[+\-*/^]|[<>:=]=|<>|\S|\s+")

HOSTILE = [
    "1e309", "-1e309", "1e-400", "nan", "inf", "0.0", "1/0.0", "99999999999999999999",
    "'a b'", "'\\n'", "'\"'", "'\\\\'", "'$x'", "'x\"\"\"'", "'é'", "_", "end", "time",
    "der", "pi", "'der(x)'", "Real", "model", "parameter", "each", "final", "(", ")",
    "[", "]", "{", "}", ";", ",", ".", "=", ":=", ":", "-", "not", "^", "\"\\\"",
    "/*", "//", "\"unterminated",
    "-(" * 4000 + "1" + ")" * 4000,
    " + ".join(["x"] * 4000),
    "sin(" * 200 + "1" + ")" * 200, "1000000000", "[1000000000]", "[1e309]", "[-1]",
]

# ------------------------------------------------------------- grammar snippets

NAMES = st.sampled_from(["x", "y", "v", "k", "n", "m.x", "a[1]", "a[n]", "b[1, 2]",
                         "'q.r'", "time", "pi"])
NUMBERS = st.sampled_from(["0", "1", "2", "0.5", "1e3", "1e309", "3", "1e-300", "nan",
                          "1000000000"])


def expressions() -> st.SearchStrategy[str]:
    leaves = st.one_of(NAMES, NUMBERS, st.just("true"))

    def grow(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        binary = st.tuples(inner, st.sampled_from(
            ["+", "-", "*", "/", "^", ".*", "<", "==", "and", "or"]), inner)
        return st.one_of(
            binary.map(lambda t: f"{t[0]} {t[1]} {t[2]}"),
            inner.map(lambda e: f"-({e})"), inner.map(lambda e: f"({e})"),
            st.tuples(st.sampled_from(["sin", "sqrt", "der", "abs", "max", "sum",
                                       "size", "fill", "zeros", "noEvent"]),
                      st.lists(inner, min_size=1, max_size=2)).map(
                lambda t: f"{t[0]}({', '.join(t[1])})"),
            st.lists(inner, min_size=1, max_size=3).map(lambda xs: "{" + ", ".join(xs) + "}"),
            st.tuples(inner, inner, inner).map(
                lambda t: f"if {t[0]} then {t[1]} else {t[2]}"),
            st.tuples(inner, inner).map(lambda t: f"{t[0]}:{t[1]}"),
        )

    return st.recursive(leaves, grow, max_leaves=8)


def snippets() -> st.SearchStrategy[str]:
    expr = expressions()
    declaration = st.tuples(
        st.sampled_from(["", "parameter ", "constant ", "flow ", "input "]),
        st.sampled_from(["Real", "Integer", "Boolean", "Units.Force"]),
        st.sampled_from(["x", "y", "v", "k", "n", "a[3]", "b[2, 2]", "a[n]"]),
        st.sampled_from(["", "(start = 1)", "(fixed = true)", "(unit = \"m\")"]),
        st.one_of(st.just(""), expr.map(lambda e: f" = {e}")),
    ).map(lambda t: f"  {t[0]}{t[1]} {t[2]}{t[3]}{t[4]};")
    equation = st.one_of(
        st.tuples(expr, expr).map(lambda t: f"  {t[0]} = {t[1]};"),
        expr.map(lambda e: f"  der(x) = {e};"),
        st.tuples(NUMBERS, expr).map(lambda t: f"  for i in 1:{t[0]} loop\n"
                                               f"    a[i] = {t[1]};\n  end for;"),
        st.tuples(expr, expr).map(lambda t: f"  if {t[0]} then\n    x = {t[1]};\n"
                                            f"  else\n    x = 0;\n  end if;"),
        st.just("  connect(p, q);"),
    )
    return st.tuples(st.lists(declaration, max_size=5), st.lists(equation, max_size=4),
                     st.sampled_from(["", "  extends SpringMass;\n",
                                      "  annotation(experiment(StopTime = 1e309));\n"])
                     ).map(lambda t: "model F\n" + "\n".join(t[0]) + "\n" + t[2]
                           + "equation\n" + "\n".join(t[1]) + "\nend F;\n")


# ------------------------------------------------------------------ mutations


@st.composite
def mutated(draw: st.DrawFn) -> str:
    source = draw(st.one_of(st.sampled_from(sorted(MODELS.values())), snippets()))
    tokens = TOKEN.findall(source)
    for _ in range(draw(st.integers(0, 4))):
        if not tokens:
            break
        i = draw(st.integers(0, len(tokens) - 1))
        action = draw(st.sampled_from(["delete", "duplicate", "swap", "hostile", "hostile"]))
        if action == "delete":
            del tokens[i]
        elif action == "duplicate":
            tokens.insert(i, tokens[i])
        elif action == "swap":
            j = draw(st.integers(0, len(tokens) - 1))
            tokens[i], tokens[j] = tokens[j], tokens[i]
        else:
            tokens[i] = draw(st.sampled_from(HOSTILE))
    return "".join(tokens)


class Hang(BaseException):
    """A command that ran past SECONDS_PER_RUN (a BaseException, so that the CLI's
    guard against internal errors does not turn it into exit 3)."""


@contextmanager
def limits(seconds: int, memory: int) -> Iterator[None]:
    """At most ``seconds`` of wall time and ``memory`` more bytes of address space (a
    huge array then fails with MemoryError instead of exhausting the machine)."""
    def expire(signum: int, frame: object) -> None:
        raise Hang(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    used = int(Path("/proc/self/statm").read_text().split()[0]) * resource.getpagesize()
    resource.setrlimit(resource.RLIMIT_AS, (used + memory, hard))
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.signal(signal.SIGALRM, previous)


# Inputs with numbers of a million or more may run loops up to the size cap (two
# million iterations, flatten/scopes/limits.py), which takes longer than the time limit on a
# loaded machine: they get a short limit, and running out of it is not a failure.
HUGE = re.compile(r"(?<![.\w])[1-9][0-9]{6,}(?![.\w])")



def invoke(*args: str, seconds: int = SECONDS_PER_RUN) -> tuple[int, str]:
    with limits(seconds, 3 << 30):
        result = CliRunner().invoke(main, list(args), prog_name="springc",
                                    catch_exceptions=False,
                                    env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.output


def run(command: str, path: Path) -> tuple[int, str]:
    """Exit code and output of ``springc COMMAND PATH``."""
    huge = HUGE.search(path.read_text()) is not None
    try:
        return invoke(command, str(path), seconds=5 if huge else SECONDS_PER_RUN)
    except Hang:
        if huge:
            return 1, "a loop within the size cap outlasted the short time limit"
        raise


@settings(max_examples=EXAMPLES, derandomize=not RANDOM, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                 HealthCheck.filter_too_much])
@given(text=mutated())
def test_check_and_flatten_never_crash(tmp_path_factory: pytest.TempPathFactory,
                                       text: str) -> None:
    path = tmp_path_factory.getbasetemp() / "fuzz.mdl"
    path.write_text(text, encoding="utf-8")
    for command in ("check", "flatten"):
        code, output = run(command, path)
        assert code in (0, 1, 2), f"{command} exit {code}:\n{output[-2000:]}\n--- input:\n{text}"
        assert "Traceback" not in output and "internal error" not in output, output[-2000:]
