"""``springc sweep`` on the command line: the files it writes, its progress and summary
on stderr, --quiet, and the exit code and message of bad options."""

from __future__ import annotations

import contextlib
import socket
import threading
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_sweep_writes_both_tables_and_reports_progress(tmp_path: Path) -> None:
    output = tmp_path / "study.parquet"
    result = CliRunner().invoke(main, [
        "sweep", SEED, "--param", "spring.k=1e3,1e4", "--param", "mass.m=0,1",
        "--stop", "0.5", "--interval", "0.1", "--vars", "mass.pos*", "--workers", "2",
        "-o", str(output)])
    assert result.exit_code == 0, result.output
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert lines[-2] == "sweep: 4/4 runs (2 failed)" + lines[-2].split("failed)")[1]
    assert lines[-1].startswith("SpringMass: 4 runs (2 ok, 2 failed), 4 simulated on 2 "
                                "local processes in ")
    assert lines[-1].endswith(f"; wrote {output} and {tmp_path / 'study.summary.parquet'}")
    table = pd.read_parquet(output)
    assert table.columns.tolist()[:6] == ["run", "time", "spring.k", "mass.m",
                                          "mass.pos[1]", "mass.pos[2]"]
    assert table["status"].tolist()[::6] == ["failed", "ok", "failed", "ok"]
    single = springc.simulate(SEED, stop=0.5, interval=0.1, outputs=["mass.pos*"],
                              parameters={"spring.k": 1e4, "mass.m": 1.0})
    last = table[table["run"] == 3][["mass.pos[1]", "mass.pos[2]"]].to_numpy()
    assert np.array_equal(last, single.values)


def test_samples_need_ranges_and_quiet_prints_nothing(tmp_path: Path) -> None:
    result = CliRunner().invoke(main, [
        "sweep", SEED, "--param", "spring.k=1e3:1e4:2", "--stop", "0.2", "--workers", "1",
        "--samples", "2", "-q", "-o", str(tmp_path / "s.parquet")])
    assert result.exit_code == 2
    assert "--samples draws values from ranges or distributions" in result.stderr
    result = CliRunner().invoke(main, [
        "sweep", SEED, "--param", "spring.k=1e3:1e4", "--stop", "0.2", "--workers", "1",
        "--samples", "2", "-q", "-o", str(tmp_path / "s.parquet")])
    assert result.exit_code == 0, result.output
    assert result.stderr == ""
    summary = pd.read_parquet(tmp_path / "s.summary.parquet")
    assert summary["spring.k"].between(1e3, 1e4).all() and len(summary) == 2


@pytest.mark.parametrize(("args", "message"), [
    (["--param", "spring.k=1,2", "-o", "x.csv"],
     "-o x.csv: the study is written as Parquet: the file name must end in .parquet"),
    (["--param", "spring.k=a", "-o", "x.parquet"], "--param spring.k=a: 'a' is not a "
     "number"),
    (["--param", "spring.k=1", "--workers", "2", "--scheduler", "tcp://x:1", "-o",
      "x.parquet"], "--workers and --scheduler exclude each other"),
])
def test_bad_options_exit_2_naming_the_option(tmp_path: Path, args: list[str],
                                              message: str,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["sweep", SEED, *args])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: " + message)


class _Service:
    """A TCP service on the loopback address that is not a Dask scheduler: it greets
    every connection with ``greeting`` (text of another protocol) or closes it."""

    def __init__(self, greeting: bytes) -> None:
        self.greeting = greeting
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self) -> None:
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            with conn, contextlib.suppress(OSError):  # the client may reset it
                if self.greeting:
                    conn.sendall(self.greeting)
                    conn.recv(1)  # until the client closes

    def close(self) -> None:
        self.server.shutdown(socket.SHUT_RDWR)  # wakes the blocked accept()
        self.server.close()
        self.thread.join(timeout=10)


@pytest.mark.parametrize(("greeting", "reason"), [
    (b"HTTP/1.1 200 OK\r\nServer: web\r\n\r\n" + b"\xff" * 64,
     "the service there does not speak Dask's protocol"),
    (b"", "the service closed the connection without a greeting"),
])
def test_a_service_that_is_not_a_scheduler_exits_2_and_leaves_nothing(
        tmp_path: Path, greeting: bytes, reason: str) -> None:
    service = _Service(greeting)
    address = f"tcp://127.0.0.1:{service.port}"
    output = tmp_path / "study.parquet"
    try:
        for _ in range(2):  # the second run is not refused for "partial results"
            result = CliRunner().invoke(main, [
                "sweep", SEED, "--param", "spring.k=1e3,1e4", "--stop", "0.2",
                "--scheduler", address, "-o", str(output)])
            assert result.exit_code == 2, result.output
            assert result.stderr.splitlines()[0] == (
                f"error: --scheduler {address}: cannot connect to a Dask scheduler "
                f"({reason})")
            assert sorted(tmp_path.iterdir()) == []
    finally:
        service.close()


def test_a_port_where_nothing_listens_exits_2_and_leaves_nothing(tmp_path: Path) -> None:
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = server.getsockname()[1]  # closed again: nothing listens there
    output = tmp_path / "study.parquet"
    result = CliRunner().invoke(main, [
        "sweep", SEED, "--param", "spring.k=1e3,1e4", "--stop", "0.2",
        "--scheduler", f"127.0.0.1:{port}", "-o", str(output)])
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines()[0] == (
        f"error: --scheduler 127.0.0.1:{port}: cannot connect to a Dask scheduler "
        "(Connection refused)")
    assert sorted(tmp_path.iterdir()) == []
