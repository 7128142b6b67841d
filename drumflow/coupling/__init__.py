"""Air acting on particles during the DEM run (one-way coupling).

:mod:`~drumflow.coupling.physics` holds the drag and heat laws, :mod:`~drumflow.coupling.library`
LIGGGHTS' C library through ctypes, :mod:`~drumflow.coupling.driver` the loop that runs as a
child process, :mod:`~drumflow.coupling.log` the reading of its logs.
"""

from __future__ import annotations

import sys

from drumflow.runner import LaunchProfile


def driver_command(profile: LaunchProfile, processes: int, spec_name: str = "coupling.json") -> list[str]:
    """The command that runs the coupling loop under the MPI launcher."""
    return profile.mpi_command([sys.executable, "-m", "drumflow.coupling.driver", spec_name], processes)
