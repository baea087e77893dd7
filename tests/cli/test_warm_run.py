"""A warm ``springc simulate`` replayed from its run record (:mod:`springc.launcher`).

Every run is a fresh process through the entry point (``springc.launcher.main``, what
the ``springc`` script and ``python -m springc`` call), which reports on stderr after
its exit which of numpy, click and numba it imported: a replay imports none of them, a
run of the command line imports click. The replay writes the same bytes and the same
summary (its time aside) as the command line, and any change of what the run depends
on sends the run back to the command line with the same result.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from springc import run_record
from springc.native import LIBRARY_FILE

SRC = str(Path(__file__).resolve().parents[2] / "src")
SEED = (Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl").read_text()
HEAVY = ("numpy", "click", "numba", "scipy", "lark", "sympy", "matplotlib")
ENTRY = f"""
import atexit, sys
def report():
    heavy = sorted({{m.split(".")[0] for m in sys.modules}} & set({HEAVY!r}))
    sys.stderr.write("IMPORTED " + " ".join(heavy) + "\\n")
atexit.register(report)
from springc.launcher import main
main(sys.argv[1:])
"""
ARGS = ("simulate", "Seed.mdl", "--stop", "2", "--interval", "0.01")


class Run:
    """One process's exit code, stdout, stderr (the time of the summary line masked)
    and the heavy packages it imported."""

    def __init__(self, done: subprocess.CompletedProcess[str]) -> None:
        lines = done.stderr.splitlines()
        assert lines and lines[-1].startswith("IMPORTED"), done.stderr
        self.code, self.stdout = done.returncode, done.stdout
        self.imported = lines[-1].split()[1:]
        self.stderr = re.sub(r", \d+\.\d\d s$", ", T s", "\n".join(lines[:-1]), flags=re.M)

    @property
    def warm(self) -> bool:
        return not self.imported


def springc_run(folder: Path, *args: str, **env: str) -> Run:
    environ = {**os.environ, "PYTHONPATH": SRC, **env}
    return Run(subprocess.run([sys.executable, "-c", ENTRY, *args], cwd=folder,
                              env=environ, capture_output=True, text=True, timeout=600,
                              check=False))


def command_line(folder: Path, *args: str) -> Run:
    """A first run: the command line, which keeps the run's record (its model compiled,
    its C loop library built into the cache)."""
    first = springc_run(folder, *args)
    assert first.code == 0 and not first.warm, first.stderr
    return first


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("SPRINGC_LOOP", "c")  # the C loop (the suite's default is numba's)
    monkeypatch.chdir(tmp_path)  # the runs' folder: their relative paths resolve alike
    (tmp_path / "Seed.mdl").write_text(SEED)
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "Extra.mo").write_text("model Extra\n  Real x;\nequation\n"
                                               "  x = 1;\nend Extra;\n")
    return tmp_path


def test_a_warm_run_writes_the_same_csv_and_summary_without_numpy_or_click(
        folder: Path) -> None:
    cold = command_line(folder, *ARGS, "-o", "seed.csv")
    written = (folder / "seed.csv").read_bytes()
    (folder / "seed.csv").unlink()
    warm = springc_run(folder, *ARGS, "-o", "seed.csv")
    assert warm.warm, warm.stderr
    assert (warm.code, warm.stdout, warm.stderr) == (0, "", cold.stderr)
    assert (folder / "seed.csv").read_bytes() == written
    assert {"click", "numpy"} <= set(cold.imported)
    assert re.fullmatch(r"SpringMass: dop853 \(auto\), [\d,]+ steps, est\. error \S+ <= "
                        r"\S+ at rtol 1e-\d+, T s", warm.stderr)
    header, first, *rows = written.decode().splitlines()
    assert header.split(",")[:5] == ["time", "mass.pos[1]", "mass.pos[2]", "mass.v[1]",
                                     "mass.v[2]"]
    assert first.split(",")[:5] == ["0.0", "1.0", "-1.0", "0.0", "0.0"]  # the start
    assert len(rows) == 200


ESTIMATED = r", est\. error \S+ <= \S+ at rtol "
AUTO = r"dop853 \(auto\), [\d,]+ steps"


@pytest.mark.parametrize(("options", "summary"), [
    (("--solver", "rk45"), rf"dop853, [\d,]+ steps{ESTIMATED}1e-9"),  # tightened: its companion
    (("--error-control", "off"), AUTO),
])
def test_the_replay_keeps_the_solver_and_error_control_asked(
        folder: Path, options: tuple[str, ...], summary: str) -> None:
    cold = command_line(folder, *ARGS, *options)
    warm = springc_run(folder, *ARGS, *options)
    assert warm.warm, warm.stderr
    assert (warm.code, warm.stdout, warm.stderr) == (0, cold.stdout, cold.stderr)
    assert re.fullmatch(f"SpringMass: {summary}, T s", warm.stderr), warm.stderr


SCENES = str(Path(__file__).resolve().parents[2] / "models" / "Scenes.mdl")


@pytest.mark.parametrize(("args", "solver"), [
    (ARGS, "bdf"),
    # 66 states: above 64 the band LU factorises in the reverse Cuthill-McKee order
    (("simulate", SCENES, "--model", "Scenes.Chain", "--set", "N=33", "--stop", "1"),
     "radau"),
])
def test_radau_and_bdf_asked_by_name_replay_on_the_c_loop(
        folder: Path, args: tuple[str, ...], solver: str) -> None:
    cold = command_line(folder, *args, "--solver", solver)
    (record,) = (folder / "cache" / run_record.RECORDS_FOLDER).glob("*.json")
    run = run_record.read(record.stem)["run"]  # type: ignore[index]
    assert (run["answer"]["solver"], run["companion"]["solver"]) == (solver, solver)
    assert (run["order"] is None) == (len(run["states"]) <= 64)
    if run["order"] is not None:
        assert sorted(run["order"]) == list(range(66)) and run["order"] != sorted(run["order"])
    warm = springc_run(folder, *args, "--solver", solver)
    assert warm.warm, warm.stderr
    assert (warm.code, warm.stdout, warm.stderr) == (0, cold.stdout, cold.stderr)
    assert re.fullmatch(rf"[\w.]+: {solver}, [\d,]+ steps{ESTIMATED}1e-\d+, T s",
                        warm.stderr), warm.stderr


def test_auto_handing_over_to_radau_keeps_no_record(folder: Path) -> None:
    stiff = folder / "Stiff.mo"
    stiff.write_text("model Stiff\n  Real x(start = 1), y(start = 0);\nequation\n"
                     "  der(x) = -1000*(x - cos(time));\n  der(y) = x;\n"
                     "  annotation(experiment(StopTime = 10));\nend Stiff;\n")
    cold = command_line(folder, "simulate", "Stiff.mo")
    assert re.match(r"Stiff: radau \(auto\), ", cold.stderr), cold.stderr
    assert not list((folder / "cache" / run_record.RECORDS_FOLDER).glob("*.json"))
    again = springc_run(folder, "simulate", "Stiff.mo")
    assert not again.warm and (again.code, again.stdout) == (0, cold.stdout)


def test_a_run_that_warns_keeps_no_record(folder: Path) -> None:
    options = ("--error-control", "warn", "--rtol", "1e-8")
    cold = command_line(folder, *ARGS, *options)
    assert "\nwarning: SpringMass: the estimated error " in cold.stderr
    again = springc_run(folder, *ARGS, *options)
    assert not again.warm and (again.code, again.stdout, again.stderr) == \
        (0, cold.stdout, cold.stderr)


def test_a_left_out_initial_condition_is_said_once_located_and_again_next_time(
        folder: Path) -> None:
    (folder / "R.mo").write_text("model R\n  Real x(start = 1, fixed = true);\n"
                                 "initial equation\n  x = 1;\nequation\n  der(x) = -x;\n"
                                 "  annotation(experiment(StopTime = 1));\nend R;\n")
    said = ("R.mo:4:3: warning: initial condition 'x = 1' left out: the other initial "
            "conditions determine it and it holds\n    4 |   x = 1;\n      |   ^^^^^\n")
    first = command_line(folder, "simulate", "R.mo", "-o", "r.csv")
    assert first.stderr.startswith(said) and first.stderr.count("warning") == 1, first.stderr
    again = springc_run(folder, "simulate", "R.mo", "-o", "r.csv")
    assert not again.warm and (again.code, again.stderr) == (0, first.stderr)
    rows = (folder / "r.csv").read_text().splitlines()
    end, x = (float(v) for v in rows[-1].split(","))
    assert end == 1 and abs(x - 0.36787944) < 1e-5  # exp(-1), rtol 1e-6


def test_a_verbose_run_keeps_no_record(folder: Path) -> None:
    command_line(folder, *ARGS, "-v")
    again = springc_run(folder, *ARGS, "-v")
    assert not again.warm and again.code == 0
    assert not list((folder / "cache" / run_record.RECORDS_FOLDER).glob("*.json"))


def test_a_warm_run_writes_the_csv_on_stdout_and_respects_quiet(folder: Path) -> None:
    cold = command_line(folder, *ARGS, "-q")
    warm = springc_run(folder, *ARGS, "-q")
    assert warm.warm
    assert (warm.code, warm.stdout, warm.stderr) == (0, cold.stdout, "")
    assert cold.stderr == "" and cold.stdout.count("\n") == 202


def test_a_changed_model_file_goes_back_to_the_command_line(folder: Path) -> None:
    command_line(folder, *ARGS, "-o", "seed.csv")
    (folder / "Seed.mdl").write_text(SEED.replace("k = 1e4, l = 1", "k = 2e4, l = 1"))
    changed = springc_run(folder, *ARGS, "-o", "seed.csv")
    assert not changed.warm and changed.code == 0
    again = springc_run(folder, *ARGS, "-o", "other.csv")  # the command line, fresh
    assert (folder / "seed.csv").read_bytes() == (folder / "other.csv").read_bytes()
    assert changed.stderr == again.stderr


def first_row(csv_text: str) -> dict[str, str]:
    header, first = csv_text.splitlines()[:2]
    return dict(zip(header.split(","), first.split(","), strict=True))


def test_a_changed_library_file_or_environment_goes_back_to_the_command_line(
        folder: Path) -> None:
    """A library file the model read, edited, sends the run back; one it never read
    (the seed reads nothing of ``lib``) does not (the record holds what the load read)."""
    (folder / "U.mo").write_text("model U\n  Extra e;\n  Real z(start = 1);\nequation\n"
                                 "  der(z) = -e.x * z;\nend U;\n")
    uses = ("simulate", "U.mo", "--stop", "1", "--interval", "0.5", "-L", "lib", "-q")
    cold, seed = command_line(folder, *uses), command_line(folder, *ARGS, "-L", "lib", "-q")
    assert springc_run(folder, *uses).warm and springc_run(folder, *ARGS, "-L", "lib", "-q").warm
    assert first_row(cold.stdout) == {"time": "0.0", "z": "1.0", "e.x": "1.0"}
    (folder / "lib" / "Extra.mo").write_text("model Extra\n  Real x;\nequation\n"
                                             "  x = 2;\nend Extra;\n")
    edited = springc_run(folder, *uses)
    assert not edited.warm and edited.code == 0
    assert first_row(edited.stdout) == {"time": "0.0", "z": "1.0", "e.x": "2.0"}
    unread = springc_run(folder, *ARGS, "-L", "lib", "-q")
    assert unread.warm and (unread.code, unread.stdout) == (0, seed.stdout)
    other_env = springc_run(folder, *ARGS, "-L", "lib", "-q", SPRINGC_TEST_FLAG="1")
    assert not other_env.warm and (other_env.code, other_env.stdout) == (0, seed.stdout)


def test_a_tampered_loop_library_is_not_loaded_and_is_built_again(folder: Path) -> None:
    cold = command_line(folder, *ARGS, "-q")
    records = list((folder / "cache" / run_record.RECORDS_FOLDER).glob("*.json"))
    assert len(records) == 1
    library = Path(run_record.read(records[0].stem)["library"]["path"])  # type: ignore[index]
    assert library.name == LIBRARY_FILE
    library.write_bytes(library.read_bytes() + b"\0")
    tampered = springc_run(folder, *ARGS, "-q")
    assert not tampered.warm and (tampered.code, tampered.stdout) == (0, cold.stdout)
    rebuilt = springc_run(folder, *ARGS, "-q")  # the command line built it again
    assert rebuilt.warm and (rebuilt.code, rebuilt.stdout) == (0, cold.stdout)


def test_a_malformed_record_is_no_record(folder: Path) -> None:
    cold = command_line(folder, *ARGS, "-q")
    (record,) = (folder / "cache" / run_record.RECORDS_FOLDER).glob("*.json")
    record.write_text('{"format": 1, "key": "' + record.stem + '", "run": 3}')
    broken = springc_run(folder, *ARGS, "-q")
    assert not broken.warm and (broken.code, broken.stdout) == (0, cold.stdout)


@pytest.mark.parametrize("kind", ["folder", "fifo"])
def test_an_output_that_is_no_regular_file_is_refused_as_the_command_line_refuses(
        folder: Path, kind: str) -> None:
    command_line(folder, *ARGS, "-o", "out.csv", "-q")
    (folder / "out.csv").unlink()
    if kind == "folder":
        (folder / "out.csv").mkdir()
    else:
        os.mkfifo(folder / "out.csv")
    refused = springc_run(folder, *ARGS, "-o", "out.csv", "-q")
    direct = subprocess.run([sys.executable, "-c", "from springc.cli import main; main()",
                             *ARGS, "-o", "out.csv", "-q"], cwd=folder,
                            env={**os.environ, "PYTHONPATH": SRC}, capture_output=True,
                            text=True, timeout=600, check=False)
    assert (refused.code, refused.stdout, refused.stderr) == \
        (direct.returncode, direct.stdout, direct.stderr.rstrip("\n"))
    assert refused.code == 2
    expected = ("is a directory" if kind == "folder" else
                "refusing to write 'out.csv': it is not a regular file")
    assert expected in refused.stderr
