"""The progress of a study on a stream: runs done out of the total, failures, ETA.

On a terminal the line is rewritten in place (at most five times a second); on a file or
pipe one line is written at each tenth of the study, so logs stay short.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TextIO


def duration(seconds: float) -> str:
    """``42 s``, ``3 min 20 s``, ``2 h 05 min``."""
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    if whole < 3600:
        return f"{whole // 60} min {whole % 60:02d} s"
    return f"{whole // 3600} h {whole % 3600 // 60:02d} min"


class StudyProgress:
    """Counts of one study; ``before`` runs were done by an earlier, resumed session."""

    def __init__(self, stream: TextIO | None, total: int, before: int = 0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.stream, self.total, self.before, self.clock = stream, total, before, clock
        self.began = clock()
        self.ok = self.failed = 0
        self.tty = bool(stream is not None and getattr(stream, "isatty", bool)())
        self.next_time = self.began
        self.next_tenth = 1

    @property
    def done(self) -> int:
        return self.before + self.ok + self.failed

    def line(self) -> str:
        """``sweep: 120/1000 runs (3 failed), 24.1 runs/s, ETA 36 s``."""
        elapsed = self.clock() - self.began
        new = self.ok + self.failed
        text = f"sweep: {self.done}/{self.total} runs ({self.failed} failed)"
        if new and elapsed > 0:
            rate = new / elapsed
            text += f", {rate:.3g} runs/s, ETA {duration((self.total - self.done) / rate)}"
        return text

    def update(self, ok: int, failed: int) -> None:
        """Count ``ok`` and ``failed`` more runs and show the line when due."""
        self.ok += ok
        self.failed += failed
        if self.stream is None:
            return
        if self.tty:
            now = self.clock()
            if now >= self.next_time or self.done == self.total:
                self.next_time = now + 0.2
                self.stream.write("\r" + self.line() + "\033[K")
                self.stream.flush()
            return
        tenth = 10 * self.done // max(1, self.total)
        if tenth >= self.next_tenth:
            self.next_tenth = tenth + 1
            self.stream.write(self.line() + "\n")
            self.stream.flush()

    def close(self) -> None:
        """End the line on a terminal."""
        if self.stream is not None and self.tty:
            self.stream.write("\n")
            self.stream.flush()
