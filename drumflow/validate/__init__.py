"""Validation against experiments (``drumflow validate``): scenes that compare the simulation
with published measurements, each with its source, what it measures and a set-up written down
before comparing (:mod:`drumflow.validate.scenes`)."""

from __future__ import annotations

from drumflow.validate.errors import ValidationDataError
from drumflow.validate.scenes import SCENES, Scene, scene

__all__ = ["SCENES", "Scene", "ValidationDataError", "scene"]
