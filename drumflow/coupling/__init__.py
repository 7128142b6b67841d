"""Air acting on particles during the DEM run (one-way coupling).

:mod:`~drumflow.coupling.spec` owns the coupling spec (built by the pipeline from the air
stage's field, run by the DEM stage), :mod:`~drumflow.physics.particle_air` the drag and heat laws,
:mod:`~drumflow.coupling.library` LIGGGHTS' C library through ctypes,
:mod:`~drumflow.coupling.driver` the loop that runs as a child process,
:mod:`~drumflow.coupling.log` the reading of its logs.
"""

from drumflow.coupling.spec import (
    COUPLING_FILE,
    CouplingSpec,
    FieldSource,
    build_coupling,
    driver_command,
)

__all__ = ["COUPLING_FILE", "CouplingSpec", "FieldSource", "build_coupling", "driver_command"]
