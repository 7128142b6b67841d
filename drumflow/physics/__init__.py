"""The physics floor: laws and properties, written once, importing nothing of drumflow but errors.

=====================  =====================================================================
``air``                dry air at 1 atm: one Incropera Table A.4, read in deg C (the drum,
                       200-600 K) or in kelvin (the grate cooler's hot air to 2000 K, with
                       its exact enthalpy)
``particle_air``       a particle in air: Schiller-Naumann drag, Ranz-Marshall heat, the
                       lumped cooling solution, terminal velocity, the coupling interval
``particle_interior``  conduction inside a particle (series solution, shells, many at once):
                       the one interior solver of the coupling loop and of every cooler
``exchanger``          the counter-current exchanger and its log-mean temperature difference
``drum_frame``         the drum's angle ``omega t`` and the rotation between lab and drum
``validation``         argument checks with one wording, the relative error, read-only arrays
=====================  =====================================================================

Every stage, analysis and reduced-order cooler takes its laws from here, so a law is tested
once, without solvers, and a mutation of it is caught by the tests of its one module
(``tests/unit/test_import_picture.py`` holds the floor: it imports errors alone).
"""
