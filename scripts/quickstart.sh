#!/usr/bin/env bash
# The main job on a fresh machine: install everything, then run the default small case end to
# end into runs/smoke (rerunning resumes or reuses what is finished).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install.sh"
cd "$here"
.venv/bin/drumflow run cases/smoke.toml --out runs/smoke "$@"
echo "results: runs/smoke/summary.json and runs/smoke/post/*.png"
