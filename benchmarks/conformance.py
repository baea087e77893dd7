"""springc against the Modelica conformance suite (modelica/Modelica-Compliance).

    PYTHONPATH=src python benchmarks/conformance.py [SUITE] [--jobs N] [--timeout S]
        [--section NAME]... [--match TEXT]... [--list CATEGORY] [--simulate] [--json out.json]

SUITE is the folder holding ``ModelicaCompliance/`` (default /work/ref/compliance; the
suite is never part of this repository). Every class annotated
``__ModelicaAssociation(TestCase(shouldPass = true|false))`` is checked in process
(load -> flatten -> balance check, as ``springc check -L SUITE --model NAME`` does), in
at most ``--jobs`` worker processes (2 by default), each model under ``--timeout``
seconds, and classified:

- ``valid-passed``: shouldPass = true and the check passes;
- ``valid-unsupported`` / ``valid-rejected``: a valid model rejected, every error saying
  "not supported" / some other error;
- ``invalid-rejected``: shouldPass = false and rejected with an error of its own;
- ``invalid-run-rejected``: (with ``--simulate``) an invalid model rejected when run;
- ``invalid-unsupported``: an invalid model rejected only with "not supported";
- ``invalid-accepted``: an invalid model wrongly accepted;
- ``crash``: an internal error (what the CLI reports with exit code 3);
- ``timeout``: the check took longer than ``--timeout``.

Valid models with an error whose help cites the specification (springc's static
rules) are listed after the table, even when another error rejects them first.

With ``--simulate``, an invalid model that ``check`` accepts and that carries an
``experiment`` annotation is simulated too: when the simulation stops with an error of
the model's own (a failing ``assert``, which the specification leaves to run time, or
a ``stateSelect`` the state choice contradicts; not "not supported" and not a code
generation limit) it counts as ``invalid-run-rejected``, rejected with its own error.

The subset (issue 15) is the language without external functions, operator records,
stream and expandable connectors and clocked features: ``conformance_scope.py`` says how
a model is classified (keywords in its code and in the suite files it names), and
``--list out-of-subset`` prints each excluded model with its reason. The table is
printed for the whole suite, then for the models inside the subset, followed by the
three target figures of issue 15 (valid models passing ``check`` and, with an
experiment, simulating; invalid models rejected with their own error; wrong accepts).

The table gives the counts per section (the top-level folder: Algorithms, Arrays,
Classes, ...). ``--list CATEGORY`` prints the models of a category with the first line
of their error. ``--simulate`` also simulates the valid models that pass and carry an
``experiment`` annotation (categories ``sim-ok``, ``sim-failed``, ``sim-crash``,
``sim-timeout``).
"""

from __future__ import annotations

import argparse
import json
import re
import signal
import subprocess
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from types import FrameType

from conformance_scope import reason as scope_reason

CHECK_CATEGORIES = ("valid-passed", "valid-unsupported", "valid-rejected",
                    "invalid-rejected", "invalid-run-rejected", "invalid-unsupported",
                    "invalid-accepted", "crash", "timeout")
SIM_CATEGORIES = ("sim-ok", "sim-failed", "sim-crash", "sim-timeout")
SHORT = {"valid-passed": "v-ok", "valid-unsupported": "v-unsup", "valid-rejected": "v-rej",
         "invalid-rejected": "i-rej", "invalid-run-rejected": "i-run",
         "invalid-unsupported": "i-unsup",
         "invalid-accepted": "i-ACC", "crash": "crash", "timeout": "tmo",
         "sim-ok": "sim-ok", "sim-failed": "sim-fail", "sim-crash": "sim-crash",
         "sim-timeout": "sim-tmo"}

_TEST_CASE = re.compile(r"__ModelicaAssociation\s*\(\s*TestCase\s*\(\s*shouldPass\s*=\s*"
                        r"(true|false)")
_WITHIN = re.compile(r"^\s*within\s+([\w.]*)\s*;", re.MULTILINE)
_IDENT = r"('(?:[^'\\]|\\.)*'|\w+)"
_HEADER = re.compile(r"^\s*(?:(?:encapsulated|partial|expandable|operator|impure|pure)\s+)*"
                     r"(?:model|block|class|package|connector|record|function|type)\s+"
                     + _IDENT + r"(\s*=)?", re.MULTILINE)
_END = re.compile(r"\bend\s+" + _IDENT + r"\s*;")


_ESCAPES = {"a": "\a", "b": "\b", "f": "\f", "n": "\n", "r": "\r", "t": "\t", "v": "\v"}


def _unescape(name: str) -> str:
    """A quoted identifier as springc stores it: without quotes, escapes resolved."""
    if not name.startswith("'"):
        return name
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(1)), name[1:-1])


def _class_at(text: str, pos: int) -> list[str]:
    """The nesting of class names (as written) around position ``pos`` of ``text``."""
    events = [(m.start(), "open", m.group(1)) for m in _HEADER.finditer(text)
              if not m.group(2)]
    events += [(m.start(), "close", m.group(1)) for m in _END.finditer(text)]
    stack: list[str] = []
    for at, kind, name in sorted(events):
        if at > pos:
            break
        if kind == "open":
            stack.append(name)
        elif stack and stack[-1] == name:
            stack.pop()
    return stack


@dataclass(frozen=True)
class TestModel:
    name: str
    section: str
    should_pass: bool
    experiment: bool
    out_of_subset: str = ""  # why the model is outside issue 15's subset, or ""


@dataclass(frozen=True)
class Outcome:
    name: str
    section: str
    valid: bool
    category: str
    message: str = ""
    sim: str = ""
    sim_message: str = ""
    rule: str = ""  # the first error citing the specification (a rule of springc's)
    out_of_subset: str = ""


class _Timeout(Exception):
    pass


def find_models(suite: Path) -> list[TestModel]:
    """Every test model of the suite: one per file, named by ``within`` and its class."""
    models = []
    for path in sorted((suite / "ModelicaCompliance").rglob("*.mo")):
        text = path.read_text(encoding="utf-8-sig", errors="replace")
        match = _TEST_CASE.search(text)
        if not match or (path.stem == "Template" and path.parent.name == "ModelicaCompliance"):
            continue
        within = _WITHIN.search(text)
        outer = _HEADER.search(text)
        if not within or not outer:
            continue
        # a test model is the file's class, or, in a package, the class holding the
        # annotation (a quoted name that no file name could store)
        nesting = _class_at(text, match.start()) if outer.group(0).strip().startswith(
            "package") else [outer.group(1)]
        name = ".".join([within.group(1), *map(_unescape, nesting)])
        section = name.split(".")[1] if name.count(".") >= 2 else "(top)"
        models.append(TestModel(name, section, match.group(1) == "true",
                                "experiment" in text, scope_reason(path, suite)))
    return models


def _alarm(signum: int, frame: FrameType | None) -> None:
    raise _Timeout


def _first_line(text: str) -> str:
    return text.strip().splitlines()[0] if text.strip() else ""


def _classify_errors(exc: BaseException) -> tuple[bool, str, str]:
    """(every error says "not supported", first error's first line, first line of the
    first error whose help cites the specification)."""
    from springc.errors import errors_of, render

    errors = errors_of(exc)  # type: ignore[arg-type]
    unsupported = all("not supported" in e.message for e in errors)
    rules = [e for e in errors if e.hint and "(Modelica 3.6, section" in e.hint]
    return (unsupported, _first_line(render(errors[0])),
            _first_line(render(rules[0])) if rules else "")


def run_one(args: tuple[TestModel, str, float, bool]) -> Outcome:
    """Check (and maybe simulate) one model in this worker process."""
    model, suite, timeout, simulate = args
    from springc.errors import ErrorGroup, SpringcError
    from springc.ir.expr import recursion_room
    from springc.pipeline import flatten_files
    from springc.simplify import check_balance

    signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    rule = ""
    try:
        with recursion_room():
            check_balance(flatten_files([], model.name, [suite]))
        category, message = ("valid-passed" if model.should_pass else "invalid-accepted"), ""
    except _Timeout:
        category, message = "timeout", f"over {timeout:g} s"
    except (SpringcError, ErrorGroup) as err:
        unsupported, message, rule = _classify_errors(err)
        if model.should_pass:
            category = "valid-unsupported" if unsupported else "valid-rejected"
        else:
            category = "invalid-unsupported" if unsupported else "invalid-rejected"
    except Exception as err:  # springc's own bug: exit 3 in the CLI
        category, message = "crash", f"{type(err).__name__}: {err}"[:300]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    scope = model.out_of_subset
    if not (simulate and category in ("valid-passed", "invalid-accepted")
            and model.experiment):
        return Outcome(model.name, model.section, model.should_pass, category,
                       message, rule=rule, out_of_subset=scope)
    sim, sim_message, own = _simulate(model, suite, timeout)
    if category == "invalid-accepted":
        if sim == "sim-failed" and own:  # rejected when run (a failing assert, ...)
            category, message = "invalid-run-rejected", sim_message
        sim, sim_message = "", ""
    return Outcome(model.name, model.section, model.should_pass, category, message, sim,
                   sim_message, rule, scope)


def _simulate(model: TestModel, suite: str, timeout: float) -> tuple[str, str, bool]:
    """(category, first line of the error, whether the error is one of the model's own:
    neither "not supported" nor a code generation limit of springc)."""
    import springc
    from springc.errors import CodegenError, ErrorGroup, SpringcError, errors_of
    from springc.ir.expr import recursion_room

    signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        with recursion_room():
            compiled = springc.compile_model([], model.name, libraries=[suite], cache=False,
                                             backend="python")  # coverage, not speed
            springc.simulate(compiled)
        return "sim-ok", "", False
    except _Timeout:
        return "sim-timeout", f"over {timeout:g} s", False
    except (SpringcError, ErrorGroup) as err:
        unsupported, message, _ = _classify_errors(err)
        own = not unsupported and not any(isinstance(e, CodegenError)
                                          for e in errors_of(err))
        return "sim-failed", message, own
    except Exception as err:
        return "sim-crash", f"{type(err).__name__}: {err}"[:300], False
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


def suite_commit(suite: Path) -> str:
    try:
        out = subprocess.run(["git", "-C", str(suite), "rev-parse", "HEAD"],
                             capture_output=True, text=True, check=True)
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"


def table(outcomes: list[Outcome], simulate: bool) -> str:
    columns = CHECK_CATEGORIES + (SIM_CATEGORIES if simulate else ())
    per: dict[str, Counter[str]] = defaultdict(Counter)
    for o in outcomes:
        for key in (o.section, "TOTAL"):
            per[key][o.category] += 1
            per[key]["n"] += 1
            if o.sim:
                per[key][o.sim] += 1
    heads = ["section", "n"] + [SHORT[c] for c in columns]
    rows = [[s, str(per[s]["n"])] + [str(per[s][c]) for c in columns]
            for s in [*sorted(k for k in per if k != "TOTAL"), "TOTAL"]]
    widths = [max(len(r[i]) for r in [*rows, heads]) for i in range(len(heads))]
    lines = ["  ".join(h.ljust(w) if i == 0 else h.rjust(w)
                       for i, (h, w) in enumerate(zip(heads, widths)))]
    lines += ["  ".join(c.ljust(w) if i == 0 else c.rjust(w)
                        for i, (c, w) in enumerate(zip(r, widths))) for r in rows]
    return "\n".join(lines)


def summary(outcomes: list[Outcome]) -> str:
    count = Counter(o.category for o in outcomes)
    valid = sum(1 for o in outcomes if o.valid)
    invalid = len(outcomes) - valid
    rejected = count["invalid-rejected"] + count["invalid-run-rejected"]
    right = count["valid-passed"] + rejected
    return (f"right: {right} of {len(outcomes)}; valid passed {count['valid-passed']} of "
            f"{valid}; invalid rejected with their own error {rejected} of {invalid} "
            f"(at run time: {count['invalid-run-rejected']}; only 'not supported': "
            f"{count['invalid-unsupported']}, wrongly accepted: "
            f"{count['invalid-accepted']}); crashes {count['crash']}, timeouts "
            f"{count['timeout']}")


def _percent(part: int, whole: int) -> str:
    return f"{part} of {whole} ({100 * part / whole:.1f} %)" if whole else "0 of 0"


def targets(outcomes: list[Outcome], simulate: bool) -> str:
    """Issue 15's three figures over ``outcomes`` (the models inside the subset)."""
    valid = [o for o in outcomes if o.valid]
    invalid = [o for o in outcomes if not o.valid]
    passing = [o for o in valid if o.category == "valid-passed" and o.sim in ("", "sim-ok")]
    rejected = [o for o in invalid if o.category in ("invalid-rejected",
                                                     "invalid-run-rejected")]
    accepted = sum(1 for o in invalid if o.category == "invalid-accepted")
    how = ("pass check and, with an experiment, simulate" if simulate else
           "pass check (simulation not run: add --simulate)")
    return (f"targets inside the subset: valid models that {how}: "
            f"{_percent(len(passing), len(valid))} [>= 90 %]; invalid models rejected "
            f"with their own error: {_percent(len(rejected), len(invalid))} [>= 95 %]; "
            f"wrongly accepted: {accepted} [0]; crashes: "
            f"{sum(1 for o in outcomes if o.category == 'crash')} [0]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("suite", nargs="?", default="/work/ref/compliance",
                        help="folder holding ModelicaCompliance/")
    parser.add_argument("--jobs", type=int, default=2, choices=(1, 2))
    parser.add_argument("--timeout", type=float, default=30.0)
    parser.add_argument("--section", action="append", default=[],
                        help="only these top-level sections (repeatable)")
    parser.add_argument("--match", action="append", default=[],
                        help="only the models whose name contains this (repeatable)")
    parser.add_argument("--list", dest="list_category", action="append", default=[],
                        choices=CHECK_CATEGORIES + SIM_CATEGORIES + ("out-of-subset",),
                        help="print the models of a category (repeatable)")
    parser.add_argument("--simulate", action="store_true",
                        help="also simulate valid models that pass and have an experiment")
    parser.add_argument("--json", type=Path, help="write every outcome to this JSON file")
    args = parser.parse_args()
    suite = Path(args.suite)
    if not (suite / "ModelicaCompliance" / "package.mo").is_file():
        parser.error(f"{suite} holds no ModelicaCompliance/package.mo")
    models = find_models(suite)
    if args.section:
        models = [m for m in models if m.section in args.section]
    if args.match:
        models = [m for m in models if any(text in m.name for text in args.match)]
    print(f"suite: {suite} at commit {suite_commit(suite)}; {len(models)} test models")
    tasks = [(m, str(suite), args.timeout, args.simulate) for m in models]
    if args.jobs == 1:
        outcomes = [run_one(t) for t in tasks]
    else:
        with ProcessPoolExecutor(args.jobs) as pool:
            outcomes = list(pool.map(run_one, tasks, chunksize=4))
    print("whole suite:")
    print(table(outcomes, args.simulate))
    print(summary(outcomes))
    inside = [o for o in outcomes if not o.out_of_subset]
    print(f"\ninside the subset ({len(inside)} models; {len(outcomes) - len(inside)} use "
          "external functions, operator records, stream or expandable connectors, "
          "or clocks):")
    print(table(inside, args.simulate))
    print(summary(inside))
    print(targets(inside, args.simulate))
    flagged = [o for o in outcomes if o.valid and o.rule]
    if flagged:  # a static rule rejecting a valid model: a wrong reject, to fix first
        print(f"\nvalid models with an error citing the specification ({len(flagged)}):")
        for o in flagged:
            print(f"  {o.name}: {o.rule}")
    for category in args.list_category:
        if category == "out-of-subset":
            chosen = [o for o in outcomes if o.out_of_subset]
        else:
            chosen = [o for o in outcomes if category in (o.category, o.sim)]
        print(f"\n{category} ({len(chosen)}):")
        for o in chosen:
            text = (o.sim_message if category.startswith("sim-") else
                    o.out_of_subset if category == "out-of-subset" else o.message)
            shown = o.name if o.name.isprintable() else repr(o.name)
            print(f"  {shown}: {text}" if text else f"  {shown}")
    if args.json:
        args.json.write_text(json.dumps([asdict(o) for o in outcomes], indent=1))


if __name__ == "__main__":
    main()
