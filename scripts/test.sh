#!/usr/bin/env bash
# Install what is missing, then hold the line: ruff and mypy must be clean, then the whole test
# suite runs (unit tests and the tiny real-solver tests, each with its own time limit) and
# reports its 15 slowest tests. Any failure fails the run. Extra arguments go to pytest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install.sh"
cd "$here"
echo "== ruff check drumflow tests scripts studies"
.venv/bin/ruff check drumflow tests scripts studies
echo "== mypy drumflow"
.venv/bin/mypy drumflow
echo "== pytest"
exec .venv/bin/python -m pytest -p no:cacheprovider -ra --durations=15 "$@" tests
