#!/usr/bin/env bash
# Ship what must outlive the machine of the reference run (studies/reference_run.sh): its newest
# full snapshot as a packed state, and its small results, into
# results/bench/reference/model_<one|two>[_fast]/.
#
#   bash studies/ship_reference.sh            # the run may be running or stopped
#   bash studies/ship_reference.sh --fast     # the fast candidate (reference_run.sh --fast)
#   bash studies/ship_reference.sh --model one [--fast]   # paper model one's
#
# The state (about 15 MB for 299,164 particles) replaces the one shipped before (git keeps the
# history); the series come from `drumflow post` and studies/ship_paper_run.py (no dumps, no
# restarts). Run it near the end of a session, when the run has written a new snapshot (every
# 0.5 s simulated).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
model="two"
fast=""
while [ $# -gt 0 ]; do
  case "$1" in
    --fast) fast="_fast" ;;  # the candidate of `reference_run.sh --fast`
    --model)
      model="${2:-}"; shift
      case "$model" in one|two) ;; *) echo "ship_reference.sh: --model ${model:-(none)}; allowed: one, two" >&2; exit 2 ;; esac ;;
    *) echo "ship_reference.sh: unknown option $1; allowed: --fast, --model one|two" >&2; exit 2 ;;
  esac
  shift
done
name="model_${model}${fast}"
run="${DRUMFLOW_REFERENCE_ROOT:-/var/tmp/drumflow-runs/reference}/$name"
dest="$here/results/bench/reference/$name"
cd "$here"
[ -f "$run/manifest.json" ] || { echo "ship_reference: no run at $run" >&2; exit 2; }
mkdir -p "$dest"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
.venv/bin/drumflow export "$run" --state --out "$tmp/state.npz" --json > "$tmp/state.json"
t="$(.venv/bin/python -c "import json,sys; print(f\"{json.load(open(sys.argv[1]))['time_s']:.3f}\")" "$tmp/state.json")"
rm -f "$dest"/state_*s.npz
mv "$tmp/state.npz" "$dest/state_${t}s.npz"
.venv/bin/drumflow post "$run" > "$tmp/post.log" 2>&1 || { cat "$tmp/post.log" >&2; exit 1; }
.venv/bin/python studies/ship_paper_run.py "$run" "$dest" --no-3d --force
cp "$run/dem/machine_load.csv" "$dest/machine_load.csv"
echo "shipped: $dest (state at ${t} s)"
