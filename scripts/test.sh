#!/usr/bin/env bash
# Install what is missing, then run the whole test suite: unit tests and the tiny real-solver
# tests (LIGGGHTS), each with its own time limit. Extra arguments go to pytest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install.sh"
cd "$here"
exec .venv/bin/python -m pytest -p no:cacheprovider -ra "$@" tests
