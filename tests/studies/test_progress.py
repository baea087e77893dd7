"""The progress of a study: counts, rate and ETA from a fake clock; one line per tenth
on a file, a rewritten line on a terminal."""

from __future__ import annotations

import io

from springc.studies.progress import StudyProgress, duration


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_durations() -> None:
    assert [duration(s) for s in (0.4, 42, 200, 7500)] == ["0 s", "42 s", "3 min 20 s",
                                                           "2 h 05 min"]


def test_a_file_gets_one_line_per_tenth_with_rate_and_eta() -> None:
    clock, stream = Clock(), io.StringIO()
    meter = StudyProgress(stream, total=20, before=0, clock=clock)
    clock.now += 4.0
    meter.update(1, 1)
    clock.now += 6.0
    meter.update(2, 1)  # 5 runs in 10 s: 0.5 runs/s, 15 left
    meter.close()
    assert stream.getvalue() == ("sweep: 2/20 runs (1 failed), 0.5 runs/s, ETA 36 s\n"
                                 "sweep: 5/20 runs (2 failed), 0.5 runs/s, ETA 30 s\n")


def test_resumed_runs_count_as_done_but_not_in_the_rate() -> None:
    clock = Clock()
    meter = StudyProgress(None, total=10, before=6, clock=clock)
    clock.now += 2.0
    meter.update(2, 0)
    assert meter.done == 8
    assert meter.line() == "sweep: 8/10 runs (0 failed), 1 runs/s, ETA 2 s"


def test_a_terminal_line_is_rewritten_and_ended() -> None:
    clock, stream = Clock(), Terminal()
    meter = StudyProgress(stream, total=3, clock=clock)
    clock.now += 1.0
    meter.update(1, 0)
    clock.now += 0.1  # within 0.2 s: not shown
    meter.update(0, 1)
    clock.now += 0.1
    meter.update(1, 0)  # the last run is always shown
    meter.close()
    assert stream.getvalue() == ("\rsweep: 1/3 runs (0 failed), 1 runs/s, ETA 2 s\033[K"
                                 "\rsweep: 3/3 runs (1 failed), 2.5 runs/s, ETA 0 s\033[K\n")
