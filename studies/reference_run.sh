#!/usr/bin/env bash
# The reference of issue 35 (time to the answer): paper model two, every particle, at the case's
# own "auto" step, to 17.5 s, in the background, on any machine, across sessions.
#
#   bash studies/reference_run.sh            # start, or go on from where it stands
#   bash studies/reference_run.sh --fast     # the candidate: the same case under the fast
#                                            # profile (`drumflow run --fast`: contact step, no
#                                            # dashpot, no conduction, the converged stop live),
#                                            # in model_two_fast/, shipped beside the reference
#   drumflow status /var/tmp/drumflow-runs/reference/model_two
#   drumflow stop   /var/tmp/drumflow-runs/reference/model_two   # a restart, then exit 130
#
# Where it goes on from, first found:
# 1. the run directory on this machine (LIGGGHTS restarts every 0.5 s): `drumflow run` resumes
#    it exactly, contact history included;
# 2. else (a fresh machine) the latest state the run shipped into git,
#    results/bench/reference/model_two/state_<t>s.npz (`drumflow export RUN --state`, packed):
#    a new run directory, its case the shipped case with run.start_state set. Its contact
#    history starts at zero at the join (measured on the smoke bed, results/bench/start_state:
#    averages unchanged, trajectories apart by a diameter within 0.1 s); each join is listed
#    in results/bench/reference/model_two/joins.csv;
# 3. else t = 0.
# The run directory is outside the work tree and never committed; what lasts is what
# `python studies/ship_reference.py` copies into results/bench/reference/model_two/.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
root="${DRUMFLOW_REFERENCE_ROOT:-/var/tmp/drumflow-runs/reference}"
name="model_two"
profile=()
case "${1:-}" in
  "") ;;
  --fast) name="model_two_fast"; profile=(--fast) ;;
  *) echo "reference_run.sh: unknown option ${1}; allowed: --fast" >&2; exit 2 ;;
esac
run="$root/$name"
shipped="$here/results/bench/reference/$name"
mkdir -p "$root"
cd "$here"

case_file="cases/paper_model_two.toml"
if [ ! -f "$run/manifest.json" ]; then
  latest="$(ls "$shipped"/state_*s.npz 2>/dev/null | sort -V | tail -n 1 || true)"
  if [ -n "$latest" ]; then
    # The shipped case with the shipped state as its start (an absolute path: the case copy
    # lives outside the work tree).
    case_file="$root/${name}_from_state.toml"
    sed "s|^\[run\]|[run]\nstart_state = \"$latest\"|" cases/paper_model_two.toml > "$case_file"
    [ -f "$shipped/joins.csv" ] || echo "joined_utc,state" > "$shipped/joins.csv"
    echo "$(date -u +%FT%TZ),$(basename "$latest")" >> "$shipped/joins.csv"
    echo "reference: a fresh machine; going on from the shipped $latest" >&2
  fi
elif [ -f "$root/${name}_from_state.toml" ]; then
  case_file="$root/${name}_from_state.toml"
elif [ -f "$root/paper_model_two_from_state.toml" ] && [ "$name" = "model_two" ]; then
  case_file="$root/paper_model_two_from_state.toml"  # the name before --fast existed
fi
exec .venv/bin/drumflow run "$case_file" "${profile[@]}" --out "$run"
