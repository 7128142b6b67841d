"""Errors of the validation scenes (``drumflow validate``)."""

from __future__ import annotations

from drumflow.errors import DrumflowError


class ValidationDataError(DrumflowError, ValueError):
    """A validation scene's input is wrong: an unknown scene or scale, a measured-data file that
    cannot be read, a run without the snapshots the comparison needs."""
