"""``python -m drumflow.cli``: the command line, as the ``drumflow`` script runs it."""

from drumflow.cli import main

main()
