"""The run directory: one per run, with a manifest, stage markers and resume state.

Layout of a run directory::

    DIR/
      manifest.json        case, its hash, versions, commands, timings, return codes
      case.toml            the validated case as it was run
      geometry/            walls.stl, geometry.json, cross_section.png
      air/                 openfoam/, field.npz, solution.json, air_cross_section.png
      dem/                 in.drum, particles.data, log.liggghts, coupling.json, dumps/,
                           restart/, coupling/
      post/                crossings.csv, mean_temperature.csv, air_heat.csv, methodology.json,
                           steps.csv, plots
      summary.json         the headline numbers
      stages/<name>.json   one marker per finished stage, with the hash of its inputs

:class:`RunDir` owns this layout: every other module asks it for a path rather than joining
file names itself. A stage is skipped when its marker holds the same input hash; a different
case in the same directory is refused rather than mixed with old results.
"""

from __future__ import annotations

import hashlib
import json
import platform
import time
from pathlib import Path
from typing import Any

from drumflow.errors import BadFileError, RunDirectoryError


def file_hash(path: Path) -> str:
    """SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def hash_text(text: str) -> str:
    """SHA-256 of a text (short cache keys for small inputs)."""
    return hashlib.sha256(text.encode()).hexdigest()


def software_versions() -> dict[str, Any]:
    """Versions of drumflow, the solvers, Python and its packages (the launch profile's lookup)."""
    from drumflow.runner import LaunchProfile

    return LaunchProfile().software_versions()


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``; ``platform.processor()`` elsewhere), for
    the machine line of benchmarks and reports."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def write_json_atomic(path: Path, data: Any) -> None:
    """Write ``data`` as JSON through a temporary file renamed over ``path``.

    A reader (``drumflow status``, a sweep's monitor polling its members) then sees the old
    file or the new one, never half of one, and a writer killed part way leaves the old file:
    a record that does not parse was damaged from outside (a copy cut, a disk filled), and the
    readers refuse it rather than guess.
    """
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2))
    tmp.replace(path)


def read_stage_marker(path: Path) -> dict[str, Any]:
    """A stage marker (``stages/<name>.json``), checked: a JSON object (its ``key`` and
    ``result`` are checked where they are used, :meth:`RunDir.stage_done`).

    A damaged marker is refused, not read as "stage not finished": the markers decide what a
    rerun keeps, and a DEM stage taken as unfinished starts afresh when no restart matches,
    deleting the run's dumps, restarts and coupling logs (``dem.stage._prepare_workdir``), so
    guessing could destroy a finished run. Markers are written whole (:func:`write_json_atomic`),
    so a damaged one never is a stage being finished right now.

    Raises
    ------
    BadFileError
        Not UTF-8, empty, cut short or not an object; the message says how to rerun the stage.
    """
    from drumflow.readers import read_json_object

    what = _marker_what(path)
    try:
        return read_json_object(path, what)
    except BadFileError as exc:
        raise BadFileError(path, exc.problem + _marker_hint(path), what) from None


def _marker_what(path: Path) -> str:
    return f"the record that the {path.stem} stage finished"


def _marker_hint(path: Path) -> str:
    """How to get past a damaged marker: delete it, and what the rerun then does."""
    stage = path.stem
    return (f"; delete it to run the {stage} stage again (`drumflow run` with the same case "
            "and --out" + (": the DEM resumes from its newest restart, or starts afresh "
                           "without one)" if stage == "dem" else ")"))


class RunDir:
    """A run directory with its manifest.

    Parameters
    ----------
    root
        The directory (created if missing).

    Raises
    ------
    BadFileError
        ``root`` is an existing file, or its ``manifest.json`` is not a readable JSON object
        (cut short, not UTF-8).
    """

    def __init__(self, root: Path | str, create: bool = True) -> None:
        from drumflow.readers import output_folder, read_json_object

        self.root = Path(root).resolve()
        if create:
            # An existing file there would end in mkdir's FileExistsError and a traceback.
            output_folder(self.root, "a run directory (--out)").mkdir(parents=True, exist_ok=True)
        self.manifest_path = self.root / "manifest.json"
        self.manifest: dict[str, Any] = (
            read_json_object(self.manifest_path, "the run's manifest")
            if self.manifest_path.exists() else {}
        )

    @classmethod
    def existing(cls, root: Path | str) -> RunDir:
        """Open a run directory to read it; never creates anything.

        Raises
        ------
        RunDirectoryError
            If ``root`` is not a directory written by ``drumflow run`` (no case file and no
            manifest).
        """
        path = Path(root).resolve()
        if not path.is_dir():
            raise RunDirectoryError(f"{path}: not a directory (expected a `drumflow run` directory)")
        rundir = cls(path, create=False)
        if not rundir.case_toml.exists() and not rundir.manifest_path.exists():
            raise RunDirectoryError(
                f"{path}: not a `drumflow run` directory (no case.toml and no manifest.json)"
            )
        return rundir

    # -- paths -------------------------------------------------------------------------
    @property
    def case_toml(self) -> Path:
        """The validated case as it was run."""
        return self.root / "case.toml"

    @property
    def summary_path(self) -> Path:
        return self.root / "summary.json"

    @property
    def stages(self) -> Path:
        return self.root / "stages"

    @property
    def logs(self) -> Path:
        return self.root / "logs"

    @property
    def geometry(self) -> Path:
        return self.root / "geometry"

    @property
    def geometry_json(self) -> Path:
        return self.geometry / "geometry.json"

    @property
    def geometry_picture(self) -> Path:
        return self.geometry / "cross_section.png"

    @property
    def air(self) -> Path:
        return self.root / "air"

    @property
    def air_openfoam(self) -> Path:
        """The OpenFOAM case of the air stage (when it was solved here, not taken from cache)."""
        return self.air / "openfoam"

    @property
    def air_field(self) -> Path:
        return self.air / "field.npz"

    @property
    def air_solution(self) -> Path:
        return self.air / "solution.json"

    @property
    def air_picture(self) -> Path:
        return self.air / "air_cross_section.png"

    @property
    def dem(self) -> Path:
        return self.root / "dem"

    @property
    def dem_dumps(self) -> Path:
        return self.dem / "dumps"

    @property
    def dem_restart(self) -> Path:
        return self.dem / "restart"

    @property
    def dem_coupling_logs(self) -> Path:
        """Per-rank logs of the coupling loop."""
        return self.dem / "coupling"

    @property
    def dem_log(self) -> Path:
        """LIGGGHTS' own log of the first (not resumed) DEM run."""
        return self.dem / "log.liggghts"

    def dem_logs(self) -> list[Path]:
        """LIGGGHTS' own logs of the DEM run and every resume."""
        return sorted(self.dem.glob("log*.liggghts"))

    @property
    def post(self) -> Path:
        return self.root / "post"

    @property
    def crossings_csv(self) -> Path:
        return self.post / "crossings.csv"

    @property
    def closures_json(self) -> Path:
        """``post/closures.json``: the slice closures ``drumflow post`` measured from the
        snapshots; shipped results keep it where they keep no snapshots."""
        return self.post / "closures.json"

    @property
    def crossings_table(self) -> Path:
        """The crossing table to read: ``post/crossings.csv``, or the gzipped copy a shipped
        results folder holds when the table is large (``post/crossings.csv.gz``)."""
        packed = self.post / "crossings.csv.gz"
        return packed if not self.crossings_csv.is_file() and packed.is_file() else self.crossings_csv

    @property
    def crossings_plot(self) -> Path:
        return self.post / "crossings.png"

    @property
    def mean_temperature_csv(self) -> Path:
        return self.post / "mean_temperature.csv"

    @property
    def mean_temperature_plot(self) -> Path:
        return self.post / "mean_temperature.png"

    @property
    def particles_plot(self) -> Path:
        """Cross-section of the particles at the end of the run."""
        return self.post / "particles_final.png"

    @property
    def air_heat_csv(self) -> Path:
        return self.post / "air_heat.csv"

    @property
    def air_heat_plot(self) -> Path:
        return self.post / "air_heat.png"

    @property
    def methodology_json(self) -> Path:
        return self.post / "methodology.json"

    @property
    def steps_csv(self) -> Path:
        """The methodology's per-step table."""
        return self.post / "steps.csv"

    # -- what the manifest records ---------------------------------------------------
    @property
    def recorded_time_step(self) -> float | None:
        """The DEM time step the run recorded (s), or None before the DEM stage chose one."""
        value = (self.manifest.get("time_step") or {}).get("time_step")
        return float(value) if value else None

    # -- case binding ------------------------------------------------------------------
    def bind_case(self, case_json: str, case_hash: str, case_toml: str, force: bool = False,
                  versions: dict[str, Any] | None = None) -> None:
        """Tie the directory to a case; refuse a different case unless ``force``.

        ``versions`` are the software versions to record (the launch profile's
        :meth:`~drumflow.runner.LaunchProfile.software_versions`; looked up when not given).

        Raises
        ------
        RunDirectoryError
            The directory already holds a run of a different case.
        """
        old = self.manifest.get("case_hash")
        if old and old != case_hash and not force:
            raise RunDirectoryError(
                f"{self.root} holds a run of a different case (hash {old[:12]}, this one "
                f"{case_hash[:12]}); choose another --out directory or pass --force"
            )
        if old != case_hash:
            # A changed case invalidates every finished stage.
            for marker in self.stages.glob("*.json"):
                marker.unlink()
        self.case_toml.write_text(case_toml)
        self.manifest.update(
            {
                "case": json.loads(case_json),
                "case_hash": case_hash,
                "case_file_sha256": hashlib.sha256(case_toml.encode()).hexdigest(),
                "versions": versions if versions is not None else software_versions(),
            }
        )
        self.manifest.setdefault("created", time.strftime("%Y-%m-%dT%H:%M:%S%z"))
        self.save()

    # -- stages ------------------------------------------------------------------------
    def _marker(self, stage: str) -> Path:
        return self.stages / f"{stage}.json"

    def _finished(self, stage: str) -> dict[str, Any] | None:
        return self.stage_record(stage)

    def stage_record(self, stage: str) -> dict[str, Any] | None:
        """The marker of a finished stage (its ``key``, ``result``, timing), or None when the
        stage has not finished.

        Raises
        ------
        BadFileError
            The marker is damaged (:func:`read_stage_marker`).
        """
        path = self._marker(stage)
        return read_stage_marker(path) if path.exists() else None

    def finished_stages(self) -> list[str]:
        """The stages with a marker, each marker checked (:func:`read_stage_marker`)."""
        markers = sorted(self.stages.glob("*.json"))
        for marker in markers:
            read_stage_marker(marker)  # refuses a damaged one (an empty object is a marker)
        return [p.stem for p in markers]

    def stage_done(self, stage: str, key: str) -> dict[str, Any] | None:
        """The stage's recorded result if it finished with the same input ``key``.

        Raises
        ------
        BadFileError
            The marker is damaged, or holds this key without a ``result`` object (the stage
            would be skipped with nothing to return).
        """
        data = self._finished(stage)
        if data is None or data.get("key") != key:
            return None
        if not isinstance(data.get("result"), dict):
            path = self._marker(stage)
            raise BadFileError(path, f"result = {data.get('result')!r}: expected the stage's "
                               "result (an object)" + _marker_hint(path), _marker_what(path))
        return data

    def finished_key(self, stage: str) -> str | None:
        """The input key the stage last finished with, or None if it has not finished."""
        data = self._finished(stage)
        return None if data is None else str(data.get("key", ""))

    def mark_done(self, stage: str, key: str, result: dict[str, Any], wall_time_s: float) -> None:
        """Record a finished stage with its input key, result and timing."""
        path = self._marker(stage)
        path.parent.mkdir(parents=True, exist_ok=True)
        data = {"key": key, "result": result, "wall_time_s": wall_time_s,
                "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
        write_json_atomic(path, data)
        self.manifest.setdefault("stages", {})[stage] = {
            "key": key,
            "wall_time_s": wall_time_s,
            "finished": data["finished"],
        }
        self.save()

    def record_commands(self, records: list[dict[str, Any]]) -> None:
        """Append program runs (command, return code, timing) to the manifest."""
        self.manifest.setdefault("commands", []).extend(records)
        self.save()

    def record(self, key: str, value: Any) -> None:
        """Store a value at the top level of the manifest."""
        self.manifest[key] = value
        self.save()

    def save(self) -> None:
        tmp = self.manifest_path.with_suffix(".tmp")
        tmp.write_text(json.dumps(self.manifest, indent=2, default=str))
        tmp.replace(self.manifest_path)  # atomic: an interrupt never leaves half a manifest

    def require(self, *paths: Path) -> None:
        """Raise :class:`RunDirectoryError` naming what is missing (paths of this directory)."""
        for path in paths:
            if not path.exists():
                rel = path.relative_to(self.root) if path.is_relative_to(self.root) else path
                raise RunDirectoryError(f"{self.root}: missing {rel}; run `drumflow run` first")
