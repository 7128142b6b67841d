"""The run directory: one per run, with a manifest, stage markers and resume state.

Layout of a run directory::

    DIR/
      manifest.json        case, its hash, versions, commands, timings, return codes
      case.toml            the validated case as it was run
      geometry/            walls.stl, geometry.json, cross_section.png
      dem/                 in.drum, particles.data, log.liggghts, dumps/, restart/
      post/                crossings.csv, mean_temperature.csv, plots
      summary.json         the headline numbers
      stages/<name>.json   one marker per finished stage, with the hash of its inputs

A stage is skipped when its marker holds the same input hash; a different case in the same
directory is refused rather than mixed with old results.
"""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path
from typing import Any

from drumflow.errors import RunDirectoryError


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


def _dpkg_version(package: str) -> str | None:
    try:
        out = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", package],
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    if out.returncode != 0:
        return None
    return out.stdout.strip() or None


def software_versions() -> dict[str, Any]:
    """Versions of drumflow, the solvers, Python and the Python packages it uses."""
    packages: dict[str, str | None] = {}
    for name in ("drumflow", "numpy", "scipy", "pandas", "gmsh", "meshio", "pyvista", "pydantic",
                 "jinja2", "foamlib", "matplotlib", "typer", "rich"):
        try:
            packages[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            packages[name] = None
    return {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "liggghts": _dpkg_version("liggghts"),
        "openfoam": _dpkg_version("openfoam"),
        "openmpi": _dpkg_version("openmpi-bin"),
        "packages": packages,
    }


class RunDir:
    """A run directory with its manifest.

    Parameters
    ----------
    root
        The directory (created if missing).
    """

    def __init__(self, root: Path | str) -> None:
        self.root = Path(root).resolve()
        self.root.mkdir(parents=True, exist_ok=True)
        self.manifest_path = self.root / "manifest.json"
        self.manifest: dict[str, Any] = (
            json.loads(self.manifest_path.read_text()) if self.manifest_path.exists() else {}
        )

    # -- paths -------------------------------------------------------------------------
    @property
    def geometry(self) -> Path:
        return self.root / "geometry"

    @property
    def dem(self) -> Path:
        return self.root / "dem"

    @property
    def post(self) -> Path:
        return self.root / "post"

    @property
    def logs(self) -> Path:
        return self.root / "logs"

    @property
    def summary_path(self) -> Path:
        return self.root / "summary.json"

    # -- case binding ------------------------------------------------------------------
    def bind_case(self, case_json: str, case_hash: str, case_toml: str, force: bool = False) -> None:
        """Tie the directory to a case; refuse a different case unless ``force``.

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
            for marker in (self.root / "stages").glob("*.json"):
                marker.unlink()
        (self.root / "case.toml").write_text(case_toml)
        self.manifest.update(
            {
                "case": json.loads(case_json),
                "case_hash": case_hash,
                "case_file_sha256": hashlib.sha256(case_toml.encode()).hexdigest(),
                "versions": software_versions(),
            }
        )
        self.manifest.setdefault("created", time.strftime("%Y-%m-%dT%H:%M:%S%z"))
        self.save()

    # -- stages ------------------------------------------------------------------------
    def _marker(self, stage: str) -> Path:
        return self.root / "stages" / f"{stage}.json"

    def stage_done(self, stage: str, key: str) -> dict[str, Any] | None:
        """The stage's recorded result if it finished with the same input ``key``."""
        path = self._marker(stage)
        if not path.exists():
            return None
        data = json.loads(path.read_text())
        return data if data.get("key") == key else None

    def mark_done(self, stage: str, key: str, result: dict[str, Any], wall_time_s: float) -> None:
        """Record a finished stage with its input key, result and timing."""
        path = self._marker(stage)
        path.parent.mkdir(parents=True, exist_ok=True)
        data = {"key": key, "result": result, "wall_time_s": wall_time_s,
                "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
        path.write_text(json.dumps(data, indent=2))
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

    def require(self, *relative: str) -> None:
        """Raise :class:`RunDirectoryError` naming what is missing."""
        for rel in relative:
            if not (self.root / rel).exists():
                raise RunDirectoryError(f"{self.root}: missing {rel}; run `drumflow run` first")
