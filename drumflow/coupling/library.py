"""LIGGGHTS as a library (``libliggghts.so.3``, the LAMMPS C API) through ctypes.

Per-atom arrays come back as numpy *views* of LIGGGHTS' own memory: reading positions and
writing heat sources or forces costs no copy and no command parsing. LIGGGHTS may reorder or
reallocate its atom arrays during a run, so views are taken afresh after every run.
"""

from __future__ import annotations

import ctypes as C
import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from drumflow.errors import SolverNotFoundError
from drumflow.runner import LIBRARY_VARIABLE, SYSTEM_LIBRARY

#: The library to load: the build the runner's launch profile named, else Debian's.
LIBRARY = os.environ.get(LIBRARY_VARIABLE, SYSTEM_LIBRARY)


def loaded_library_path() -> str | None:
    """The file of the LIGGGHTS library this process has mapped (from ``/proc/self/maps``), or
    ``None``: which build really ran, whatever the variables said (a benchmark records it)."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return None
    for line in maps.splitlines():
        parts = line.split(maxsplit=5)
        if len(parts) == 6 and "libliggghts" in Path(parts[5]).name:
            return parts[5].strip()
    return None


class Liggghts:
    """One LIGGGHTS instance in this process (or, under mpirun, on MPI_COMM_WORLD).

    Parameters
    ----------
    args
        Command-line arguments, e.g. ``["-log", "log.liggghts", "-echo", "none"]``.
    """

    def __init__(self, args: list[str]) -> None:
        try:
            lib = C.CDLL(LIBRARY, mode=C.RTLD_GLOBAL)
        except OSError as exc:
            raise SolverNotFoundError(
                "liggghts", [LIBRARY], None, None,
                reason=f"{LIBRARY} not found ({exc}); run scripts/install.sh"
            ) from None
        lib.lammps_open_no_mpi.argtypes = [C.c_int, C.POINTER(C.c_char_p), C.POINTER(C.c_void_p)]
        lib.lammps_command.argtypes = [C.c_void_p, C.c_char_p]
        lib.lammps_command.restype = C.c_char_p
        lib.lammps_file.argtypes = [C.c_void_p, C.c_char_p]
        lib.lammps_extract_atom.argtypes = [C.c_void_p, C.c_char_p]
        lib.lammps_extract_atom.restype = C.c_void_p
        lib.lammps_extract_fix.argtypes = [C.c_void_p, C.c_char_p, C.c_int, C.c_int, C.c_int, C.c_int]
        lib.lammps_extract_fix.restype = C.c_void_p
        lib.lammps_extract_global.argtypes = [C.c_void_p, C.c_char_p]
        lib.lammps_extract_global.restype = C.c_void_p
        lib.lammps_extract_compute.argtypes = [C.c_void_p, C.c_char_p, C.c_int, C.c_int]
        lib.lammps_extract_compute.restype = C.c_void_p
        lib.lammps_close.argtypes = [C.c_void_p]
        self._lib = lib
        argv_list = [b"liggghts", *[a.encode() for a in args]]
        argv = (C.c_char_p * len(argv_list))(*argv_list)
        self._handle = C.c_void_p()
        lib.lammps_open_no_mpi(len(argv_list), argv, C.byref(self._handle))

    def file(self, path: Path) -> None:
        """Run every command of an input file."""
        self._lib.lammps_file(self._handle, str(path).encode())

    def command(self, text: str) -> None:
        """Run one command."""
        self._lib.lammps_command(self._handle, text.encode())

    @property
    def nlocal(self) -> int:
        """Particles owned by this process."""
        ptr = self._lib.lammps_extract_global(self._handle, b"nlocal")
        return int(C.cast(ptr, C.POINTER(C.c_int))[0])

    def atom_vector(self, name: str) -> NDArray[np.float64]:
        """A per-atom scalar (``radius``, ``rmass``) as a view, length nlocal."""
        ptr = self._lib.lammps_extract_atom(self._handle, name.encode())
        return self._view(ptr, name)

    def atom_array(self, name: str) -> NDArray[np.float64]:
        """A per-atom 3-vector (``x``, ``v``) as an (nlocal, 3) view."""
        ptr = self._lib.lammps_extract_atom(self._handle, name.encode())
        if not ptr:
            raise KeyError(f"LIGGGHTS has no per-atom array {name!r}")
        rows = C.cast(ptr, C.POINTER(C.POINTER(C.c_double)))
        n = self.nlocal
        if n == 0:
            return np.empty((0, 3))
        return np.ctypeslib.as_array(rows[0], shape=(n, 3))

    def fix_vector(self, fix_id: str) -> NDArray[np.float64]:
        """A per-atom scalar property of a fix (``Temp``, ``heatSource``, property/atom)."""
        ptr = self._lib.lammps_extract_fix(self._handle, fix_id.encode(), 1, 1, 0, 0)
        return self._view(ptr, fix_id)

    def fix_array(self, fix_id: str, columns: int) -> NDArray[np.float64]:
        """A per-atom vector property of a fix (``property/atom ... vector``) as an
        (nlocal, columns) view; LIGGGHTS keeps each atom's values contiguous."""
        ptr = self._lib.lammps_extract_fix(self._handle, fix_id.encode(), 1, 2, 0, 0)
        n = self.nlocal
        if n == 0:
            return np.empty((0, columns))
        if not ptr:
            raise KeyError(f"LIGGGHTS has no per-atom array {fix_id!r}")
        rows = C.cast(ptr, C.POINTER(C.POINTER(C.c_double)))
        return np.ctypeslib.as_array(rows[0], shape=(n, columns))

    def compute_atom_vector(self, compute_id: str) -> NDArray[np.float64]:
        """A per-atom vector of a compute (evaluated now if not at this step), length nlocal."""
        ptr = self._lib.lammps_extract_compute(self._handle, compute_id.encode(), 1, 1)
        return self._view(ptr, compute_id)

    def _view(self, ptr: int | None, name: str) -> NDArray[np.float64]:
        n = self.nlocal
        if n == 0:
            # A rank without particles (an open scene before its first feed) may hold no
            # array at all; a wrong name is still refused once it has particles.
            return np.empty(0)
        if not ptr:
            raise KeyError(f"LIGGGHTS has no per-atom quantity {name!r}")
        return np.ctypeslib.as_array(C.cast(ptr, C.POINTER(C.c_double)), shape=(n,))

    def close(self) -> None:
        if self._handle:
            self._lib.lammps_close(self._handle)
            self._handle = C.c_void_p()
