"""Report stage: plots (matplotlib PNG) of a run's observables."""
