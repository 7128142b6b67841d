"""Reading LIGGGHTS text dumps (``dump custom``), fast, into numpy arrays; packing snapshots.

meshio cannot read these files (and calls ``sys.exit`` on some failures), so drumflow reads
them itself: a dump is nine header lines and a whitespace table, which pandas' C parser reads
at tens of MB/s.

A full snapshot of paper model one is 40 MB of text (467,443 particles) and takes half a second
to parse; 36 of them made ``drumflow post`` slow and the run large. :func:`pack_dumps` turns
each finished snapshot into ``snap.STEP.npz`` (id as int32, positions, velocities and radius as
float32, which keep 7.2 significant digits against the text's 8, i.e. 0.1 um at 1.5 m;
temperature as float64, every digit of the text): about half the size, read in milliseconds.
What does not vary is not repeated: a column with one value for every particle (the radius of
a monodisperse bed; every column of the first snapshot but the positions) is kept as that
value, and ids that run 1, 2, ..., N (no particle lost) as their first; 3.7 of model one's
18.7 MB per snapshot. :func:`read_dump` and :func:`dump_files` take either form, the packed
one first.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.errors import BadFileError, RunDirectoryError

_STEP_RE = re.compile(r"(\d+)")


@dataclass(frozen=True)
class Snapshot:
    """One dump: the time step number and a column table, rows sorted by particle id."""

    step: int
    columns: dict[str, NDArray[np.float64]]

    @property
    def ids(self) -> NDArray[np.int64]:
        return self.columns["id"].astype(np.int64)

    def __len__(self) -> int:
        return len(self.columns["id"])


def _canonical(name: str) -> str:
    # "f_Temp[0]" -> "T": the heat fix's per-atom temperature column.
    return "T" if name.startswith("f_Temp") else name


#: Suffix of a packed snapshot.
PACKED = ".npz"
#: Columns packed as float32 (the rest as float64, ``id`` as int32).
_SINGLE = frozenset({"x", "y", "z", "vx", "vy", "vz", "radius", "fx", "fy", "fz",
                     "omegax", "omegay", "omegaz"})


def read_dump(path: Path) -> Snapshot:
    """Read one LIGGGHTS ``dump custom`` text file, or its packed form (``.npz``).

    Raises
    ------
    RunDirectoryError
        When the file is not a LIGGGHTS custom dump (names the file and what is wrong); a
        :class:`~drumflow.errors.BadFileError` when it is cut short (inside its header, in a
        row, or rows missing), not UTF-8, or holds a word where a number belongs.
    """
    if path.suffix == PACKED:
        return _read_packed(path)
    what = "a particle dump of the DEM run"
    try:
        with path.open("r", encoding="utf-8") as fh:
            header = [fh.readline() for _ in range(9)]
    except UnicodeDecodeError as exc:
        raise BadFileError(path, f"not UTF-8 text in its header (byte 0x{exc.object[exc.start]:02x})",
                           what) from None
    if header[0].startswith("ITEM: TIMESTEP") and not header[8]:
        raise BadFileError(path, "ends inside its 9-line header: cut short?", what)
    if not header[0].startswith("ITEM: TIMESTEP") or not header[8].startswith("ITEM: ATOMS"):
        raise RunDirectoryError(f"{path}: not a LIGGGHTS custom dump (bad header)")
    try:
        step = int(header[1])
        natoms = int(header[3])
    except ValueError:
        raise RunDirectoryError(f"{path}: unreadable step or atom count in the header") from None
    names = [_canonical(n) for n in header[8].split()[2:]]
    if natoms == 0:
        return Snapshot(step, {n: np.empty(0) for n in names})
    # LIGGGHTS ends every row with a newline. A file cut inside its last row still has the
    # header's count of rows, the cut one padded with NaN (or a number cut to fewer digits):
    # the row count cannot see it, the last byte can.
    with path.open("rb") as fh:
        fh.seek(-1, os.SEEK_END)
        if fh.read(1) != b"\n":
            raise BadFileError(path, "ends inside a row (no end of line after the last one): "
                               "cut short, or still being written", what)
    try:
        table = pd.read_csv(
            path,
            sep=" ",
            header=None,
            skiprows=9,
            usecols=range(len(names)),  # LIGGGHTS ends each row with a space: one empty column
            dtype=np.float64,
            engine="c",
        ).to_numpy()
    except UnicodeDecodeError as exc:
        raise BadFileError(path, f"not UTF-8 text (byte 0x{exc.object[exc.start]:02x} in the "
                           "rows)", what) from None
    except ValueError as exc:  # a word where a number belongs, a row of another width
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise BadFileError(path, f"not a table of numbers after the header ({first})", what) from None
    if len(table) != natoms:
        raise BadFileError(path, f"header says {natoms} particles, table has {len(table)} "
                           "(truncated dump?)", what)
    order = np.argsort(table[:, names.index("id")], kind="stable")
    table = table[order]
    return Snapshot(step, {n: np.ascontiguousarray(table[:, i]) for i, n in enumerate(names)})


def _read_packed(path: Path) -> Snapshot:
    from drumflow.errors import BadFileError
    from drumflow.readers import read_npz

    try:
        data = read_npz(path)
    except BadFileError as exc:
        # Still a RunDirectoryError: the readers that skip a newest dump still being written
        # skip a cut archive (BadZipFile) the same way.
        raise BadFileError(path, f"not a packed drumflow snapshot ({exc.problem})") from None
    try:
        names = [str(n) for n in data["names"]]
        step = int(data["step"])
        # Files packed before constant columns were elided have no row count.
        rows = int(data["rows"]) if "rows" in data else None
        columns = {}
        for n in names:
            if f"first_{n}" in data:
                if rows is None:
                    raise ValueError(f"column {n} kept as its first value, but no row count")
                columns[n] = np.arange(rows, dtype=np.float64) + float(data[f"first_{n}"])
                continue
            values = np.asarray(data[f"c_{n}"], dtype=np.float64)
            if rows is not None and values.shape == (1,) and rows != 1:
                values = np.full(rows, values[0])
            columns[n] = np.ascontiguousarray(values)
    except (KeyError, ValueError) as exc:
        raise RunDirectoryError(f"{path}: not a packed drumflow snapshot ({exc})") from None
    return Snapshot(step, columns)


def dump_step(path: Path) -> int:
    """The time step a dump file's name carries (``snap.<step>.txt`` or ``.npz``); -1 if none."""
    return _step_of(path)


def _step_of(p: Path) -> int:
    m = _STEP_RE.findall(p.name)
    return int(m[-1]) if m else -1


def dump_files(folder: Path, prefix: str = "snap") -> list[Path]:
    """The dump files ``PREFIX.<step>.txt`` (or packed, ``.npz``) of a folder in time order;
    of a step found in both forms, the packed one."""
    by_step: dict[int, Path] = {}
    for p in folder.glob(f"{prefix}.*.txt"):
        if p.is_file():
            by_step.setdefault(_step_of(p), p)
    for p in folder.glob(f"{prefix}.*{PACKED}"):
        if p.is_file():
            by_step[_step_of(p)] = p  # written whole, then renamed: complete when present
    return [by_step[k] for k in sorted(by_step)]


def pack_dump(path: Path) -> Path:
    """Pack one text dump into ``.npz`` beside it and remove the text; return the new path.

    The packed file is written under a temporary name and renamed, so that a reader (or a
    run stopped half way) never sees a partial one; the text goes only after the rename.
    """
    snap = read_dump(path)
    target = path.with_suffix(PACKED)
    arrays: dict[str, NDArray[np.generic]] = {
        "step": np.array(snap.step, dtype=np.int64),
        "names": np.array(list(snap.columns), dtype=np.str_),
    }
    rows = len(snap)
    arrays["rows"] = np.array(rows, dtype=np.int64)
    for name, values in snap.columns.items():
        dtype = np.int32 if name == "id" else np.float32 if name in _SINGLE else np.float64
        packed = values.astype(dtype)
        if name == "id" and rows and np.array_equal(values, values[0] + np.arange(rows)):
            arrays[f"first_{name}"] = np.array(values[0], dtype=np.int64)
        elif rows > 1 and np.all(packed == packed[0]):
            arrays[f"c_{name}"] = packed[:1]
        else:
            arrays[f"c_{name}"] = packed
    partial = target.with_name(target.name + ".partial")
    with partial.open("wb") as fh:
        np.savez(fh, **arrays)  # type: ignore[arg-type]
    os.replace(partial, target)
    path.unlink()
    return target


def pack_dumps(folder: Path, prefix: str = "snap", keep_newest: int = 0,
               skip_unreadable: bool = False) -> list[Path]:
    """Pack every text dump ``PREFIX.*.txt`` of ``folder`` but the ``keep_newest`` newest (while
    LIGGGHTS runs, the newest may still be being written). Returns the packed files.

    Raises
    ------
    RunDirectoryError
        A dump is not readable (cut short, say), unless ``skip_unreadable``: it then stays text
        and the others are packed.
    """
    texts = sorted((p for p in folder.glob(f"{prefix}.*.txt") if p.is_file()), key=_step_of)
    packed = []
    for path in texts[: max(0, len(texts) - keep_newest)]:
        try:
            packed.append(pack_dump(path))
        except RunDirectoryError:
            if not skip_unreadable:
                raise
    return packed


@dataclass(frozen=True)
class DumpSeries:
    """A time series of dumps with a fixed particle set, as (time, particle) arrays."""

    steps: NDArray[np.int64]
    times: NDArray[np.float64]
    ids: NDArray[np.int64]
    fields: dict[str, NDArray[np.float64]]  # each (n_times, n_particles)
    counts: NDArray[np.int64]  # particles present in each dump
    skipped: tuple[Path, ...] = ()  # the newest file, left out because it is cut short

    def __getitem__(self, name: str) -> NDArray[np.float64]:
        return self.fields[name]


def _read_files(files: list[Path], skip_partial_newest: bool) -> tuple[list[Snapshot], tuple[Path, ...]]:
    """Read the dumps; with ``skip_partial_newest``, leave out the newest when it cannot be read
    (LIGGGHTS is still writing it, or a kill cut it short)."""
    snaps = [read_dump(f) for f in files[:-1]]
    try:
        snaps.append(read_dump(files[-1]))
    except RunDirectoryError:
        if not skip_partial_newest or len(files) < 2:
            raise
        return snaps, (files[-1],)
    return snaps, ()


def read_series(
    folder: Path,
    time_step: float,
    columns: tuple[str, ...] = ("x", "y", "z", "T"),
    prefix: str = "snap",
    skip_partial_newest: bool = False,
) -> DumpSeries:
    """Read every dump of a folder into arrays over (time, particle).

    Particles missing from a dump (lost) get NaN there, so a loss never shifts rows; the
    per-dump counts are kept for reporting. ``skip_partial_newest``: a newest dump that cannot
    be read (a run still writing it) is left out and named in :attr:`DumpSeries.skipped`.

    Raises
    ------
    RunDirectoryError
        When the folder has no dumps, a dump lacks a requested column, or a dump cannot be read.
    """
    files = dump_files(folder, prefix)
    if not files:
        raise RunDirectoryError(f"{folder}: no dump files ({prefix}.*.txt or .npz)")
    snaps, skipped = _read_files(files, skip_partial_newest)
    files = files[: len(snaps)]
    for f, s in zip(files, snaps, strict=True):
        missing = [c for c in columns if c not in s.columns]
        if missing:
            raise RunDirectoryError(f"{f}: dump lacks column(s) {', '.join(missing)}")
    first = snaps[0].ids
    # Rows are sorted by id: with no particle lost (the usual case) every dump has the same ids,
    # and the union is the first's. np.unique over all of them took 1.5 s for model one's
    # first eight snapshots and grew with every one (drumflow post on a 17.5 s run).
    same = all(len(s) == len(first) and np.array_equal(s.ids, first) for s in snaps[1:])
    ids = first if same else np.unique(np.concatenate([s.ids for s in snaps]))
    fields = {c: np.full((len(snaps), len(ids)), np.nan) for c in columns}
    for i, s in enumerate(snaps):
        pos = slice(None) if same else np.searchsorted(ids, s.ids)
        for c in columns:
            fields[c][i, pos] = s.columns[c]
    steps = np.array([s.step for s in snaps], dtype=np.int64)
    return DumpSeries(
        steps=steps,
        times=(steps * time_step).astype(np.float64),
        ids=ids,
        fields=fields,
        counts=np.array([len(s) for s in snaps], dtype=np.int64),
        skipped=skipped,
    )


@dataclass(frozen=True)
class DumpRows:
    """Dumps whose particle sets change from file to file, as one long table.

    Row ``k`` is particle ``ids[k]`` in dump number ``frame[k]`` (time ``times[frame[k]]``).
    The crossing dump holds only the particles near the axis plane, so its memory grows with
    the rows written, not with (dumps x particles).
    """

    steps: NDArray[np.int64]
    times: NDArray[np.float64]
    frame: NDArray[np.int64]
    ids: NDArray[np.int64]
    fields: dict[str, NDArray[np.float64]]
    skipped: tuple[Path, ...] = ()  # the newest file, left out because it is cut short

    def __getitem__(self, name: str) -> NDArray[np.float64]:
        return self.fields[name]


def read_rows(folder: Path, time_step: float, prefix: str = "cross",
              skip_partial_newest: bool = False) -> DumpRows:
    """Read every ``PREFIX.*.txt`` dump of a folder into a :class:`DumpRows` table
    (``skip_partial_newest`` as in :func:`read_series`).

    Raises
    ------
    RunDirectoryError
        When the folder has no such dumps, or one cannot be read.
    """
    files = dump_files(folder, prefix)
    if not files:
        raise RunDirectoryError(f"{folder}: no dump files ({prefix}.*.txt)")
    snaps, skipped = _read_files(files, skip_partial_newest)
    names = [n for n in snaps[0].columns if n != "id"]
    frame = np.concatenate([np.full(len(s), i, dtype=np.int64) for i, s in enumerate(snaps)])
    ids = np.concatenate([s.ids for s in snaps])
    fields = {n: np.concatenate([s.columns[n] for s in snaps]) for n in names}
    steps = np.array([s.step for s in snaps], dtype=np.int64)
    return DumpRows(steps, (steps * time_step).astype(np.float64), frame, ids, fields, skipped)
