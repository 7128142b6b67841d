"""Progress of a run's stages on the command line: bars on a terminal, lines in a log file.

A paper-scale run goes in the background for hours (``nohup drumflow run ... > run.log &``).
Rich draws its bars only on a terminal, so such a log stayed empty until the end; there,
:class:`StageProgress` writes one plain line per stage every :data:`PLAIN_EVERY_S` wall seconds
and when the stage ends, with the rate and ETA of this call (a resumed run's earlier attempts
are not in the rate).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from types import TracebackType

from rich.console import Console
from rich.progress import (
    BarColumn,
    Progress,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

__all__ = ["PLAIN_EVERY_S", "StageProgress", "resume_hint"]

#: Wall seconds between two plain progress lines of one stage.
PLAIN_EVERY_S = 60.0


def _clock_text(seconds: float) -> str:
    seconds = max(0, round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


class StageProgress:
    """The ``progress(stage, done, total)`` callback of :func:`drumflow.pipeline.run_case`.

    Parameters
    ----------
    console
        Where to draw (standard error).
    prefix
        Put before each stage's name (the case's name, when several cases run).
    plain
        Plain lines instead of bars; default: when ``console`` is not a terminal.
    every_s, clock
        Wall seconds between plain lines, and the clock (tests pass their own).
    """

    def __init__(self, console: Console, prefix: str = "", plain: bool | None = None,
                 every_s: float = PLAIN_EVERY_S, clock: Callable[[], float] = time.monotonic) -> None:
        self.console = console
        self.prefix = prefix
        self.plain = (not console.is_terminal) if plain is None else plain
        self.every_s = every_s
        self.clock = clock
        self._bar: Progress | None = None
        self._tasks: dict[str, TaskID] = {}
        # Per stage: (wall and done at its first report, wall of the last line written).
        self._first: dict[str, tuple[float, float]] = {}
        self._last_line: dict[str, float] = {}
        self._ended: set[str] = set()

    def __enter__(self) -> StageProgress:
        if not self.plain:
            columns = (TextColumn("[bold]{task.description}"), BarColumn(),
                       TextColumn("{task.fields[sim]}"), TimeElapsedColumn(), TextColumn("ETA"),
                       TimeRemainingColumn())
            self._bar = Progress(*columns, console=self.console, transient=False)
            self._bar.__enter__()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        if self._bar is not None:
            self._bar.__exit__(kind, value, traceback)

    def __call__(self, stage: str, done: float, total: float) -> None:
        name = f"{self.prefix}{stage}"
        if self._bar is not None:
            # One bar per stage; a stage may change its total (the air stage ends with (1, 1)
            # when it converges before air.max_iterations), so the bar finishes.
            if stage not in self._tasks:
                self._tasks[stage] = self._bar.add_task(name, total=total, sim="")
            sim = f"{done:.3f}/{total:.3f} s simulated" if stage == "dem" else ""
            self._bar.update(self._tasks[stage], completed=done, total=total, sim=sim)
            if done >= total:
                self._bar.stop_task(self._tasks[stage])
            return
        self._plain_line(stage, done, total)

    def line(self, stage: str, done: float, total: float, now: float | None = None) -> str:
        """The plain line for a report at ``now`` (default: the clock's time)."""
        now = self.clock() if now is None else now
        t0, done0 = self._first.setdefault(stage, (now, done))
        elapsed = now - t0
        share = done / total if total > 0 else 1.0
        text = f"{self.prefix}{stage}: "
        text += (f"{done:.3f}/{total:.3f} s simulated" if stage == "dem"
                 else f"{done:g}/{total:g}")
        text += f" ({share:.1%}), elapsed {_clock_text(elapsed)}"
        if done >= total:
            return text + ", done"
        rate = (done - done0) / elapsed if elapsed > 0 else 0.0
        if rate > 0:
            text += f", ETA {_clock_text((total - done) / rate)}"
            if stage == "dem":
                text += f" ({1.0 / rate:,.0f} wall s per simulated s)"
        return text

    def _plain_line(self, stage: str, done: float, total: float) -> None:
        if stage in self._ended:
            return
        now = self.clock()
        first = stage not in self._first
        text = self.line(stage, done, total, now)
        ended = done >= total
        if first or ended or now - self._last_line.get(stage, -float("inf")) >= self.every_s:
            self._last_line[stage] = now
            self.console.print(text, highlight=False, markup=False, soft_wrap=True)
        if ended:
            self._ended.add(stage)


def resume_hint(out: Path) -> str:
    """What to do after an interrupted run in ``out``, and where its resume starts."""
    from drumflow.analysis.run_status import run_status

    where = ""
    try:
        status = run_status(out)
    except Exception:  # interrupted before the run directory was complete: say nothing more
        status = None
    if status is not None:
        where = (" (no restart yet: it starts again from 0 s)" if status.restart_time_s is None else
                 f" (from its restart at {status.restart_time_s:.4g} s, step {status.restart_step:,})")
    return f"run the same command again to resume into {out}{where}"
