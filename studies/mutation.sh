#!/usr/bin/env bash
# Mutation testing of the cooler models, the coupling laws and the air tables (issue 36).
# Installs mutmut into .venv when it is missing, then runs studies/mutation.py on a copy of the
# tracked files under /tmp (mutmut 3 writes a mutants/ tree; the work tree is left alone).
# Writes results/mutation/summary.json and results/mutation/survivors_raw/<module>.md.
#   bash studies/mutation.sh                       # every module (hours on 2 cores)
#   bash studies/mutation.sh --modules physics air_properties curtain
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
if ! .venv/bin/python -c "import mutmut" 2>/dev/null; then
    .venv/bin/pip install "mutmut>=3.3,<4"
fi
exec .venv/bin/python studies/mutation.py "$@"
