#!/usr/bin/env bash
# Install what is missing, then hold the line: ruff and mypy must be clean, the documentation
# site must build without a warning, then the whole test suite runs (unit tests and the tiny
# real-solver tests, each with its own time limit) and reports its 15 slowest tests. Any failure
# fails the run. Extra arguments go to pytest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install.sh"
cd "$here"
echo "== ruff check drumflow tests scripts studies docs"
.venv/bin/ruff check drumflow tests scripts studies docs
echo "== mypy drumflow"
.venv/bin/mypy drumflow
echo "== mkdocs build --strict"
# Warnings (a broken link, a missing picture, a docstring mkdocstrings cannot read) fail the
# build. The two variables silence banners that plugins print about MkDocs' future (not warnings).
DISABLE_MKDOCS_2_WARNING=true NO_MKDOCS_2_WARNING=1 \
  .venv/bin/mkdocs build --strict --quiet --site-dir /tmp/drumflow-site
echo "== pytest"
exec .venv/bin/python -m pytest -p no:cacheprovider -ra --durations=15 "$@" tests
