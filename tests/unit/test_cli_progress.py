"""Progress lines of a run in a log file (drumflow.cli._progress): a background run's log was
empty until the end, because rich draws its bars only on a terminal."""

from __future__ import annotations

import io

from rich.console import Console

from drumflow.cli._progress import StageProgress


class _Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def _progress(every_s: float = 60.0) -> tuple[StageProgress, io.StringIO, _Clock]:
    buffer = io.StringIO()
    clock = _Clock()
    console = Console(file=buffer, width=300)  # a file, not a terminal
    return StageProgress(console, every_s=every_s, clock=clock), buffer, clock


def test_a_log_file_gets_plain_lines_with_rate_and_eta() -> None:
    progress, buffer, clock = _progress()
    assert progress.plain
    with progress:
        progress("dem", 12.0, 17.5)  # a resumed run: its first report is not at zero
        for k in range(1, 31):  # 1 s of simulated time per 300 wall s, reported every 10 s
            clock.now += 10.0
            progress("dem", 12.0 + k / 30.0, 17.5)
    lines = buffer.getvalue().splitlines()
    # The first report, then one line per minute: 30 reports over 300 s give 5 more.
    assert len(lines) == 6, lines
    assert lines[0].startswith("dem: 12.000/17.500 s simulated (68.6%), elapsed 0:00:00")
    # 4.5 simulated s left at 300 wall s per simulated s: 1,350 s.
    assert lines[-1] == ("dem: 13.000/17.500 s simulated (74.3%), elapsed 0:05:00, ETA 0:22:30 "
                         "(300 wall s per simulated s)")


def test_the_end_of_a_stage_is_written_once_and_stages_are_apart() -> None:
    progress, buffer, clock = _progress()
    with progress:
        progress("air", 0, 300)
        clock.now += 5.0
        progress("air", 1, 1)  # converged early: the air stage ends with (1, 1)
        progress("air", 1, 1)
        progress("dem", 0.0, 1.0)
    lines = buffer.getvalue().splitlines()
    assert lines == ["air: 0/300 (0.0%), elapsed 0:00:00", "air: 1/1 (100.0%), elapsed 0:00:05, done",
                     "dem: 0.000/1.000 s simulated (0.0%), elapsed 0:00:00"]


def test_a_terminal_gets_bars_not_lines() -> None:
    buffer = io.StringIO()
    console = Console(file=buffer, force_terminal=True, width=120)
    with StageProgress(console) as progress:
        assert not progress.plain
        progress("dem", 0.5, 1.0)
    assert "0.500/1.000 s simulated" in buffer.getvalue()


def test_tables_off_a_terminal_are_not_cut_at_80_columns(monkeypatch) -> None:
    """Regression: in a log or pipe rich drew every table 80 columns wide and cut the bench's
    and the summary's columns to "…"."""
    import io

    from rich.table import Table

    from drumflow.cli._guard import LOG_WIDTH, cli_console

    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.setattr("sys.stdout", io.StringIO())
    console = cli_console()
    assert console.width == LOG_WIDTH
    table = Table("variant", "particle_steps_per_s", "speedup_vs_baseline", "physics_ok", "description")
    table.add_row("no_conduction", "2,021,690", "1.29", "True", "no heat fix, the loop integrates")
    console.print(table)
    text = console.file.getvalue()  # type: ignore[attr-defined]
    assert "particle_steps_per_s" in text and "…" not in text
    monkeypatch.setenv("COLUMNS", "100")
    assert cli_console().width == 100
