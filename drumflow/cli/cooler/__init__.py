"""`drumflow cooler ...`: the command group of the reduced-order cooler models.

One module per model registers its commands on :data:`app`.
"""

from drumflow.cli.cooler import curtain, drum, fluid_bed, grate  # noqa: F401  (registers commands)
from drumflow.cli.cooler._app import app

__all__ = ["app"]
