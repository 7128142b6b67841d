"""Analysis: observables from dumps and the paper's heat-transfer methodology."""
