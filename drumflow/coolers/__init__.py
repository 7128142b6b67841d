"""Reduced-order models of whole coolers, run in seconds on a laptop, no solver needed.

- ``curtain``: a particle curtain falling through a gas stream (Wardjiman and Rhodes 2009).
- ``drum``: the whole flighted rotary drum, with closures from a drumflow slice run.
- ``fluid_bed`` and ``refrigeration``: the vibrating fluidised-bed cooler and its ammonia
  refrigeration cycle.
- ``grate``: the clinker grate cooler (cross-flow finite volumes, TDMA).

- ``plant`` and ``prediction``: the full-scale drum's definition, and its outlets predicted
  from a slice run's h or a Nu-Re-Pr correlation (the paper's exchanger model).

Every model takes its laws from :mod:`drumflow.physics` (one particle-interior solver,
:mod:`~drumflow.physics.particle_interior`, shared by all of them). Reduced-order models never
import the solver stages: a slice run's results reach them through :mod:`drumflow.analysis`.
"""
