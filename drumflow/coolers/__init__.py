"""Reduced-order models of whole coolers, run in seconds on a laptop, no solver needed.

- :mod:`~drumflow.coolers.particle_interior`: one radial conduction solver for a particle,
  shared by every model below.
- ``curtain``: a particle curtain falling through a gas stream (Wardjiman and Rhodes 2009).
- ``drum``: the whole flighted rotary drum, with closures from a drumflow slice run.
- ``fluid_bed`` and ``refrigeration``: the vibrating fluidised-bed cooler and its ammonia
  refrigeration cycle.
- ``grate``: the clinker grate cooler (cross-flow finite volumes, TDMA).

Reduced-order models never import the solver stages: a slice run's results reach them
through :mod:`drumflow.analysis`.
"""

from drumflow.coolers.particle_interior import Sphere, SphereConduction

__all__ = ["Sphere", "SphereConduction"]
