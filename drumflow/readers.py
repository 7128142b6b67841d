"""Readers of the files drumflow takes in: every failure names the file and what is wrong.

A case file, a closures file, a weather table or a run directory's manifest, tables and arrays
can arrive damaged: written in another encoding, cut short by a full disk or a killed process,
emptied, or holding ``NaN`` where a number belongs. Python's own readers then raise
``UnicodeDecodeError``, ``JSONDecodeError``, ``EmptyDataError`` or ``BadZipFile`` without the
file's name, and the command ends in a traceback; worse, a table cut at a line boundary reads
as a shorter, valid one. Each reader here raises :class:`~drumflow.errors.BadFileError` (exit
code 2) naming the file and the problem instead, and the commands reach their files through
them.

Missing files are the callers' business (each knows which command writes the file), except
where a reader is asked for a file it must have.
"""

from __future__ import annotations

import json
import math
import zipfile
import zlib
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from drumflow.errors import BadFileError

if TYPE_CHECKING:
    import pandas as pd
    from pydantic import ValidationError

__all__ = [
    "field_problems",
    "output_file",
    "output_folder",
    "read_csv",
    "read_json",
    "read_json_object",
    "read_json_object_if_present",
    "read_npz",
    "read_text",
    "reaches_time",
]


def read_text(path: Path | str, what: str = "") -> str:
    """The file's text, decoded as UTF-8.

    Raises
    ------
    BadFileError
        The file is missing, a directory, unreadable, or not UTF-8 (the byte, its offset and
        line named).
    """
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise BadFileError(p, "no such file", what) from None
    except IsADirectoryError:
        raise BadFileError(p, "a directory, not a file", what) from None
    except OSError as exc:
        raise BadFileError(p, f"cannot be read ({exc.strerror or exc})", what) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise BadFileError(p, f"not UTF-8 text: byte 0x{data[exc.start]:02x} at offset {exc.start} "
                           f"(line {line}); save it as UTF-8", what) from None


def _not_json(path: Path, text: str, exc: json.JSONDecodeError, what: str) -> BadFileError:
    # A decoder stopping at the very end of the text, or in a string that never closes, means
    # the file was cut short (a killed writer, a full disk): say so, it is the common case.
    cut = exc.pos >= len(text.rstrip()) or exc.msg.startswith("Unterminated string")
    return BadFileError(path, f"not valid JSON ({exc.msg}, line {exc.lineno} column {exc.colno})"
                        + ("; the file ends there: cut short?" if cut else ""), what)


def read_json(path: Path | str, what: str = "") -> Any:
    """The file's JSON value.

    ``NaN`` and ``Infinity`` tokens (which Python's encoder writes and JSON does not allow) are
    read as floats: the caller's validation says whether a field may hold one.

    Raises
    ------
    BadFileError
        Missing, not UTF-8, empty, or not valid JSON (where it stops, and whether the file
        ends there).
    """
    p = Path(path)
    text = read_text(p, what)
    if not text.strip():
        raise BadFileError(p, "empty (no JSON value)", what)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise _not_json(p, text, exc, what) from None


def read_json_object(path: Path | str, what: str = "") -> dict[str, Any]:
    """:func:`read_json` of a file that must hold a JSON object.

    Raises
    ------
    BadFileError
        As :func:`read_json`, or the value is not an object.
    """
    data = read_json(path, what)
    if not isinstance(data, dict):
        raise BadFileError(path, f"holds a JSON {type(data).__name__}, expected an object "
                           "({...})", what)
    return data


def read_json_object_if_present(path: Path | str, what: str = "") -> dict[str, Any] | None:
    """:func:`read_json_object`, or None when the file does not exist.

    For the files a run writes late or not at all (``summary.json``, cached results): a missing
    one is a fact to report, but a damaged one (cut short, not UTF-8, not an object) is still
    refused by name, since dropping it would show the run without it, and without a word.
    """
    if not Path(path).exists():
        return None
    return read_json_object(path, what)


def read_csv(
    path: Path | str,
    what: str = "",
    *,
    columns: Iterable[str] = (),
    finite: Iterable[str] = (),
    min_rows: int = 0,
    usecols: list[str] | None = None,
) -> pd.DataFrame:
    """A CSV table (``.csv`` or gzipped ``.csv.gz``, told by the name), checked.

    Parameters
    ----------
    path, what
        The file, and what it holds (for the messages).
    columns
        Columns the header must have.
    finite
        Columns whose every value must be a finite number (a word, an empty cell, ``nan`` or
        ``inf`` is refused with its row).
    min_rows
        The least number of data rows.
    usecols
        Read only these columns (pandas' ``usecols``).

    Raises
    ------
    BadFileError
        Missing, not UTF-8, empty, not a CSV table, a truncated gzip stream, a missing column,
        too few rows or a non-finite value (the first one named by row and column).
    """
    import pandas as pd

    p = Path(path)
    if not p.is_file():
        raise BadFileError(p, "no such file" if not p.exists() else "not a file", what)
    try:
        table = pd.read_csv(p, usecols=usecols)
    except pd.errors.EmptyDataError:
        raise BadFileError(p, "empty: no header and no rows", what) from None
    except UnicodeDecodeError as exc:
        raise BadFileError(p, f"not UTF-8 text: byte 0x{exc.object[exc.start]:02x} at offset "
                           f"{exc.start}; save it as UTF-8", what) from None
    except pd.errors.ParserError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise BadFileError(p, f"not a CSV table ({first})", what) from None
    except (EOFError, OSError, zlib.error) as exc:
        # gzip raises EOFError ("Compressed file ended before the end-of-stream marker") for a
        # cut .gz, BadGzipFile (an OSError) for one that is not gzip at all.
        raise BadFileError(p, f"truncated or not readable ({exc})", what) from None
    except ValueError as exc:  # usecols naming a column the header lacks
        raise BadFileError(p, f"not the expected table ({exc})", what) from None
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise BadFileError(p, f"no column(s) {', '.join(missing)} in the header "
                           f"({','.join(map(str, table.columns))})", what)
    if len(table) < min_rows:
        raise BadFileError(p, f"{len(table)} data row(s); at least {min_rows} needed", what)
    for column in finite:
        values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            row = int(bad[0])
            raise BadFileError(p, f"column {column}, data row {row + 1} (line {row + 2}): "
                               f"{table[column].iloc[row]!r} is not a finite number", what)
    return table


def read_npz(path: Path | str, what: str = "") -> dict[str, NDArray[Any]]:
    """Every array of a ``.npz`` archive, read in full (so a damaged member fails here, not
    later at first use).

    Raises
    ------
    BadFileError
        Missing, truncated (``BadZipFile``, an early end of file, a bad CRC or deflate stream),
        or not an ``.npz`` archive.
    """
    p = Path(path)
    try:
        loaded = np.load(p, allow_pickle=False)
    except FileNotFoundError:
        raise BadFileError(p, "no such file", what) from None
    except (zipfile.BadZipFile, EOFError, zlib.error) as exc:
        raise BadFileError(p, f"not a complete .npz archive (truncated?): {exc}", what) from None
    except (OSError, ValueError) as exc:
        raise BadFileError(p, f"not a .npz archive ({exc})", what) from None
    if not isinstance(loaded, np.lib.npyio.NpzFile):
        raise BadFileError(p, "a single .npy array, not a .npz archive", what)
    try:
        with loaded:
            return {name: loaded[name] for name in loaded.files}
    except (zipfile.BadZipFile, EOFError, zlib.error, OSError, ValueError) as exc:
        raise BadFileError(p, f"a damaged .npz archive (truncated?): {exc}", what) from None


def reaches_time(path: Path, last_time_s: float, summary: Path,
                 tolerance_s: float = 1e-6) -> None:
    """Refuse a time series of a run that ends before the run does.

    ``drumflow post`` writes a run's series and its ``summary.json`` together, the summary's
    ``simulated_time_s`` being the series' last time; a series that ends earlier was cut short
    (a copy interrupted, a disk filled), and averaging it would give a wrong answer in silence.

    Parameters
    ----------
    path
        The series (for the message).
    last_time_s
        Its last time, s.
    summary
        The run's ``summary.json``; nothing is checked when it is missing or records no time
        (a run not post-processed yet).
    tolerance_s
        Allowed shortfall, s (the series' times are written with 10 significant digits).

    Raises
    ------
    BadFileError
        The series ends before the summary's simulated time, or the summary is damaged.
    """
    if not summary.is_file():
        return
    recorded = read_json_object(summary, "the run's summary").get("simulated_time_s")
    if not isinstance(recorded, int | float) or not math.isfinite(recorded):
        return
    if last_time_s < float(recorded) - max(tolerance_s, 1e-9 * abs(float(recorded))):
        raise BadFileError(path, f"ends at {last_time_s:.6g} s, before the {float(recorded):.6g} s "
                           f"of simulated time {summary} records: cut short? Rerun `drumflow post "
                           f"{summary.parent}` (or restore the file)")


def output_folder(path: Path | str, option: str = "--out") -> Path:
    """``path`` as a folder to write into: refused when it exists and is not a folder.

    Raises
    ------
    BadFileError
        ``path`` is an existing file (or anything but a directory).
    """
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise BadFileError(p, f"an existing file, not a folder; allowed for {option}: a folder "
                           "(new or existing)")
    return p


def output_file(path: Path | str, option: str = "--out") -> Path:
    """``path`` as a file to write: refused when it is an existing folder.

    Raises
    ------
    BadFileError
        ``path`` is an existing directory.
    """
    p = Path(path)
    if p.is_dir():
        raise BadFileError(p, f"an existing folder, not a file; allowed for {option}: a file "
                           "path (new, or an existing file to replace)")
    return p


def field_problems(exc: ValidationError, data: dict[str, Any]) -> list[str]:
    """One line per problem of a pydantic validation of ``data``: the field (its dotted path),
    its value and what is allowed."""
    lines = []
    for err in exc.errors():
        loc = err["loc"]
        name = ".".join(str(part) for part in loc) or "(file)"
        value: Any = data
        for part in loc:  # down to the value itself (nested models, lists)
            if isinstance(value, dict):
                value = value.get(part)
            elif isinstance(value, list) and isinstance(part, int) and part < len(value):
                value = value[part]
            else:
                value = None
        shown = "missing" if err["type"] == "missing" else f"= {value!r}"
        lines.append(f"{name} {shown}: {err['msg']}")
    return lines
