"""``MPI_Allreduce`` for the coupling loop, through ctypes.

No MPI binding for Python is installed, and the loop needs only sums over ranks; LIGGGHTS'
``lammps_open_no_mpi`` has already initialised MPI and loaded ``libmpi`` globally.
"""

from __future__ import annotations

import ctypes as C
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["allreduce_sum"]


def _mpi_handles(lib: C.CDLL) -> tuple[Any, Any, Any]:
    """(MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD) for the loaded MPI library.

    Open MPI's handles are addresses of global objects; MPICH's are integer constants (mpi.h).
    """
    try:
        return (C.c_void_p(C.addressof(C.c_char.in_dll(lib, "ompi_mpi_double"))),
                C.c_void_p(C.addressof(C.c_char.in_dll(lib, "ompi_mpi_op_sum"))),
                C.c_void_p(C.addressof(C.c_char.in_dll(lib, "ompi_mpi_comm_world"))))
    except ValueError:
        return C.c_int(0x4C00080B), C.c_int(0x58000003), C.c_int(0x44000000)


def allreduce_sum(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Element-wise sum over all MPI ranks; every rank must call it with the same length.

    Raises
    ------
    RuntimeError
        When MPI reports an error.
    """
    send = np.ascontiguousarray(values, dtype=np.float64)
    recv = np.empty_like(send)
    lib = C.CDLL(None)
    double, op, comm = _mpi_handles(lib)
    status = lib.MPI_Allreduce(send.ctypes.data_as(C.c_void_p), recv.ctypes.data_as(C.c_void_p),
                               C.c_int(send.size), double, op, comm)
    if status != 0:
        raise RuntimeError(f"MPI_Allreduce failed with code {status}")
    return recv
