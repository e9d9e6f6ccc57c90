"""Progress of a sweep on stderr: a tqdm bar on a terminal, else one line about every 10%."""
from __future__ import annotations

import sys
import time


class Progress:
    """Counts finished scenarios out of ``total``, ``done`` of them from an earlier run."""

    def __init__(self, total: int, done: int = 0, stream=None):
        self.total, self.done, self.new = total, done, 0
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()
        self._bar = None
        self._next = 0
        if self.stream.isatty():
            from tqdm import tqdm
            self._bar = tqdm(total=total, initial=done, unit="scenario", desc="sweep",
                             file=self.stream)
        else:
            self._step = max(1, round(total / 10))
            self._next = (done // self._step + 1) * self._step
            if done:
                self._line(f"resuming: {done} of {total} scenarios already done")

    def _line(self, text: str) -> None:
        print(f"sweep: {text}", file=self.stream, flush=True)

    def update(self) -> None:
        self.done += 1
        self.new += 1
        if self._bar is not None:
            self._bar.update(1)
            return
        if self.done >= self._next or self.done == self.total:
            elapsed = time.perf_counter() - self.t0
            left = elapsed / self.new * (self.total - self.done)
            self._line(f"{self.done}/{self.total} scenarios ({100 * self.done / self.total:.0f}%), "
                       f"{elapsed:.1f} s, about {left:.0f} s left")
            while self._next <= self.done:
                self._next += self._step

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
