"""Output files under hostile conditions (issue 10): what ``-o``/``--plot`` may replace,
the writer chosen by suffix, all-or-nothing outputs, signals and closed pipes.

No test points an output at a device: a FIFO made in ``tmp_path`` stands for one.
"""

from __future__ import annotations

import csv
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.errors import UsageError

MODEL = """
model Decay
  parameter Real k = 2 "Decay rate";
  Real x(start = 1, unit = "m") "Amount left";
equation
  der(x) = -k*x;
end Decay;
"""

SRC = str(Path(__file__).resolve().parents[2] / "src")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def model(tmp_path: Path) -> Path:
    path = tmp_path / "Decay.mdl"
    path.write_text(MODEL)
    return path


def run(*args: str | Path) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, [str(a) for a in args])
    return result.exit_code, result.stdout, result.stderr


def simulate(model: Path, *args: str | Path) -> tuple[int, str, str]:
    return run("simulate", model, "--stop", "1", "--interval", "0.25", "-q", *args)


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".part"))


def test_fifo_is_refused_without_writing(model: Path, tmp_path: Path) -> None:
    fifo = tmp_path / "out.csv"
    os.mkfifo(fifo)
    code, _, err = simulate(model, "-o", fifo)
    assert code == 2
    assert err == (f"error: -o: refusing to write '{fifo}': it is not a regular file (a "
                   "device, FIFO or socket)\nhelp: springc writes its outputs to regular "
                   "files only\n")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert leftovers(tmp_path) == []


def test_symlink_to_a_fifo_is_refused(model: Path, tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    link = tmp_path / "plot.png"
    link.symlink_to(fifo)
    code, _, err = simulate(model, "--plot", link)
    assert code == 2 and "it is not a regular file" in err
    assert link.is_symlink() and stat.S_ISFIFO(os.stat(link).st_mode)


def test_symlink_to_a_regular_file_is_followed(model: Path, tmp_path: Path) -> None:
    """The file the link points to is replaced; the link stays a link."""
    (tmp_path / "data").mkdir()
    target = tmp_path / "data" / "real.csv"
    target.write_text("old\n")
    target.chmod(0o640)
    link = tmp_path / "out.csv"
    link.symlink_to(target)
    code, _, err = simulate(model, "-o", link)
    assert code == 0, err
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text().splitlines()[0] == "time,x"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640  # the replaced file keeps its mode
    assert leftovers(tmp_path) == [] and leftovers(tmp_path / "data") == []


def test_folder_target_and_missing_or_read_only_folder(model: Path, tmp_path: Path) -> None:
    (tmp_path / "dir.csv").mkdir()
    code, _, err = simulate(model, "-o", tmp_path / "dir.csv")
    assert code == 2 and "is a directory" in err  # click's own check of -o
    missing = tmp_path / "nowhere" / "out.csv"
    code, _, err = simulate(model, "-o", missing)
    assert code == 2
    assert err.startswith(f"error: -o: cannot write '{missing}': the folder "
                          f"'{tmp_path / 'nowhere'}' does not exist\n")
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        code, _, err = simulate(model, "--plot", locked / "p.png")
    finally:
        locked.chmod(0o755)
    assert code == 2
    assert err == (f"error: --plot: cannot write '{locked / 'p.png'}': the folder "
                   f"'{locked}' is read-only\n")
    assert list(locked.iterdir()) == []


def test_read_only_file_is_not_overwritten(model: Path, tmp_path: Path) -> None:
    out = tmp_path / "kept.csv"
    out.write_text("precious\n")
    out.chmod(0o444)
    code, _, err = simulate(model, "-o", out)
    assert code == 2
    assert err == (f"error: -o: cannot write '{out}': the file is read-only\n"
                   "help: make it writable (chmod u+w) or choose another path\n")
    assert out.read_text() == "precious\n"


def test_input_file_is_never_an_output(model: Path, tmp_path: Path) -> None:
    as_csv = tmp_path / "Decay.csv"  # a model file whose name has a result suffix
    as_csv.write_text(MODEL)
    code, _, err = simulate(as_csv, "-o", as_csv)
    assert code == 2 and "it is an input of this run" in err
    assert as_csv.read_text() == MODEL
    hard = tmp_path / "hard.csv"
    os.link(model, hard)  # the same file under another name
    code, _, err = simulate(model, "-o", hard)
    assert code == 2 and "it is an input of this run" in err
    assert model.read_text() == MODEL


def test_output_and_plot_must_differ(model: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    alias = tmp_path / "alias.png"
    alias.symlink_to(out)
    code, _, err = simulate(model, "-o", out, "--plot", alias)
    assert code == 2
    assert err == (f"error: -o and --plot name the same file '{alias}'\n"
                   "help: give each output its own file\n")
    assert not out.exists()


def test_unknown_suffixes_are_refused(model: Path, tmp_path: Path) -> None:
    code, _, err = simulate(model, "-o", tmp_path / "out.txt")
    assert code == 2
    assert err == (f"error: -o {tmp_path / 'out.txt'}: the suffix must be one of .csv, "
                   ".mat (it chooses the format)\n")
    code, _, err = simulate(model, "--plot", tmp_path / "p.gif")
    assert code == 2 and "the suffix must be one of .png, .svg, .pdf" in err
    assert list(tmp_path.glob("out.*")) == [] and list(tmp_path.glob("p.*")) == []


def test_mat_file_in_the_openmodelica_layout(model: Path, tmp_path: Path) -> None:
    from scipy.io import loadmat

    out = tmp_path / "Decay_res.mat"
    code, _, err = simulate(model, "-o", out)
    assert code == 0, err
    mat = loadmat(str(out), chars_as_strings=False)

    def strings(matrix: np.ndarray) -> list[str]:  # binTrans: one name per column
        return ["".join(column).rstrip() for column in zip(*matrix)]

    assert ["".join(row).rstrip() for row in mat["Aclass"]] == [
        "Atrajectory", "1.1", "", "binTrans"]
    assert strings(mat["name"]) == ["time", "k", "x"]
    # the model's description strings, units in brackets (as Dymola writes them)
    assert strings(mat["description"]) == ["Time in [s]", "Decay rate", "Amount left [m]"]
    # time; the parameter k in data_1 (row 2); x in data_2 (row 2)
    assert mat["dataInfo"].T.tolist() == [[0, 1, 0, -1], [1, 2, 0, 0], [2, 2, 0, -1]]
    assert mat["data_1"].tolist() == [[0.0, 1.0], [2.0, 2.0]]
    time = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    assert mat["data_2"][0].tolist() == time.tolist()
    np.testing.assert_allclose(mat["data_2"][1], np.exp(-2 * time), rtol=1e-5)


def test_mat_descriptions_outside_latin_1_are_replaced(tmp_path: Path) -> None:
    from scipy.io import loadmat

    model = tmp_path / "R.mdl"
    model.write_text('model R\n  parameter Real r = 2 "Resistance in \u03a9";\n'
                     '  Real x(start = 1) "\u00b5-scale";\nequation\n  der(x) = -x/r;\n'
                     'end R;\n', encoding="utf-8")
    out = tmp_path / "r.mat"
    code, _, err = simulate(model, "-o", out, "--error-estimate", "off")
    assert code == 0, err
    mat = loadmat(str(out), chars_as_strings=False)
    assert ["".join(c).rstrip() for c in zip(*mat["description"])] == [
        "Time in [s]", "Resistance in ?", "\u00b5-scale"]


def test_mat_file_keeps_the_error_estimate_and_no_side_file(model: Path,
                                                             tmp_path: Path) -> None:
    from scipy.io import loadmat

    out = tmp_path / "x.mat"
    code, _, err = simulate(model, "-o", out, "--error-estimate", "on")
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Decay.mdl", "x.mat"]
    mat = loadmat(str(out), chars_as_strings=False)
    assert ["".join(c).rstrip() for c in zip(*mat["errorEstimateName"])] == ["x"]
    absolute, relative, at_time = mat["errorEstimate"][:, 0]
    # relative to the largest |x| on the grid, x(0) = 1; the error of a 1e-6 run
    assert relative == absolute and 0 < absolute < 1e-5 and 0 <= at_time <= 1


def test_mat_file_with_parameters_in_data_1(model: Path) -> None:
    import io

    from scipy.io import loadmat

    import springc
    from springc.simulation.results import write_mat

    result = springc.simulate(model, stop=1.0, interval=0.5, parameters={"k": 3.0})
    buffer = io.BytesIO()
    write_mat(result, buffer)
    mat = loadmat(io.BytesIO(buffer.getvalue()), chars_as_strings=False)
    names = ["".join(c).rstrip() for c in zip(*mat["name"])]
    assert names == ["time", "k", "x"]
    assert mat["dataInfo"][:, 1].tolist() == [1, 2, 0, 0]  # k: block 1, row 2
    assert mat["data_1"][1].tolist() == [3.0, 3.0]


def test_plot_format_follows_the_suffix(model: Path, tmp_path: Path) -> None:
    code, _, err = simulate(model, "--plot", tmp_path / "p.svg", "-o", tmp_path / "p.pdf.csv")
    assert code == 0, err
    assert (tmp_path / "p.svg").read_bytes().lstrip().startswith(b"<?xml")
    assert b"<svg" in (tmp_path / "p.svg").read_bytes()[:2000]
    code, _, err = simulate(model, "--plot", tmp_path / "p.pdf")
    assert code == 0, err
    assert (tmp_path / "p.pdf").read_bytes().startswith(b"%PDF-")


def test_mathtext_in_a_unit_neither_fails_nor_leaves_half_the_outputs(
        tmp_path: Path) -> None:
    model = tmp_path / "U.mdl"
    model.write_text('model U\n  Real x(start = 1, unit = "$\\\\oops{m}$");\nequation\n'
                     "  der(x) = -x;\nend U;\n")
    code, _, err = simulate(model, "-o", tmp_path / "u.csv", "--plot", tmp_path / "u.png")
    assert code == 0, err
    assert (tmp_path / "u.csv").read_text().startswith("time,x\n")
    assert (tmp_path / "u.png").read_bytes().startswith(b"\x89PNG")


def test_a_failing_plot_leaves_no_csv(model: Path, tmp_path: Path,
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    import springc.simulation.results as results

    def broken(*args: object) -> bytes:
        raise ValueError("cannot draw")

    monkeypatch.setattr(results, "render_plot", broken)
    code, _, err = simulate(model, "-o", tmp_path / "a.csv", "--plot", tmp_path / "a.png")
    assert code == 3 and "cannot draw" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Decay.mdl"]


def test_quotes_and_backslashes_in_names_keep_the_csv_header(tmp_path: Path) -> None:
    model = tmp_path / "Q.mdl"
    model.write_text("model Q\n  Real 'a\"b'(start = 1);\n  Real 'c,d\\\\e'(start = 2);\n"
                     "equation\n  der('a\"b') = 0;\n  der('c,d\\\\e') = 0;\nend Q;\n")
    out = tmp_path / "q.csv"
    code, _, err = simulate(model, "-o", out)
    assert code == 0, err
    assert out.read_text().splitlines()[0] == 'time,"a""b","c,d\\e"'  # RFC 4180
    with out.open(newline="") as f:
        header = next(csv.reader(f))
    assert header == ["time", 'a"b', "c,d\\e"]


def test_interrupt_exits_130_without_aborted(model: Path, tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    import springc.api

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(springc.api, "simulate", interrupted)
    code, _, err = simulate(model, "-o", tmp_path / "out.csv")
    assert code == 130
    assert err == "interrupted\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Decay.mdl"]


SIGTERM_SCRIPT = """
import os, signal, sys
import springc.simulation.results as results
from springc.cli import main
from springc.errors import UsageError

def write_then_terminated(result, f):
    f.write("time,x\\n")
    f.flush()
    os.kill(os.getpid(), signal.SIGTERM)
    f.write("never\\n")

results.write_csv = write_then_terminated
main(sys.argv[1:])
"""


def test_sigterm_during_a_write_removes_the_part_file(model: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    out.write_text("previous\n")
    env = {**os.environ, "PYTHONPATH": SRC}
    done = subprocess.run([sys.executable, "-c", SIGTERM_SCRIPT, "simulate", str(model),
                           "--stop", "1", "-q", "-o", str(out)],
                          capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 143, done.stderr
    assert leftovers(tmp_path) == []
    assert out.read_text() == "previous\n"
    assert "Traceback" not in done.stderr


def test_closed_stdout_pipe_exits_quietly(model: Path) -> None:
    env = {**os.environ, "PYTHONPATH": SRC}
    command = [sys.executable, "-m", "springc", "simulate", str(model), "--stop", "100",
               "--interval", "0.0001", "-q"]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          env=env) as proc:
        assert proc.stdout is not None and proc.stderr is not None
        assert proc.stdout.readline() == b"time,x\n"
        proc.stdout.close()  # as `| head -1` does
        err = proc.stderr.read()
        code = proc.wait(timeout=120)
    assert err == b""
    assert code == 141  # 128 + SIGPIPE, as a tool killed by the closed pipe


def test_flat_output_escapes_quoted_names_and_reads_back(tmp_path: Path) -> None:
    model = tmp_path / "Q.mdl"
    model.write_text("model Q\n  Real 'a\\'b'(start = 1);\n  Real 'c\"d\\\\e'(start = 2);\n"
                     "equation\n  der('a\\'b') = -'a\\'b';\n  der('c\"d\\\\e') = 0;\nend Q;\n")
    code, flat, err = run("flatten", model)
    assert code == 0, err
    assert flat == ("model Q\n  Real 'a\\'b'(start = 1);\n  Real 'c\"d\\\\e'(start = 2);\n"
                    "equation\n  der('a\\'b') = -'a\\'b';\n  der('c\"d\\\\e') = 0;\nend Q;\n")
    again = tmp_path / "Q2.mdl"
    again.write_text(flat)
    code, flat_again, err = run("flatten", again)
    assert code == 0, err
    assert flat_again == flat


def test_api_writers_choose_by_suffix(model: Path, tmp_path: Path) -> None:
    import springc

    result = springc.simulate(model, stop=1.0, interval=0.5, error_control="off")
    with pytest.raises(UsageError, match=r"^error: plot .*p\.gif: the suffix must be one of "
                                         r"\.png, \.svg, \.pdf"):
        result.plot(tmp_path / "p.gif")
    result.save(tmp_path / "r.csv")
    assert (tmp_path / "r.csv").read_text().startswith("time,x\n0.0,1.0\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Decay.mdl", "r.csv"]
    # with an error estimate, still only the file named
    estimated = springc.simulate(model, stop=1.0, interval=0.5, error_control="warn")
    assert estimated.error_estimate is not None
    estimated.save(tmp_path / "r2.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Decay.mdl", "r.csv", "r2.csv"]


def test_a_symlink_to_nothing_is_refused(model: Path, tmp_path: Path) -> None:
    """Following it would create a file the user never named (in another folder)."""
    (tmp_path / "elsewhere").mkdir()
    target = tmp_path / "elsewhere" / "planted.py"
    link = tmp_path / "out.py"
    link.symlink_to(target)
    code, _, err = run("compile", model, "-q", "-o", link)
    assert code == 2
    assert err == (f"error: -o: refusing to write '{link}': it is a symbolic link to "
                   f"'{target}', which does not exist\nhelp: springc replaces the file a "
                   "link points to, and creates no file where a link points: remove the "
                   "link or choose another path\n")
    assert not target.exists() and link.is_symlink()
