#!/usr/bin/env bash
# The references of issue 35 (time to the answer): a paper model, every particle, at the case's
# own "auto" step, to 17.5 s, in the background, on any machine, across sessions.
#
#   bash studies/reference_run.sh            # model two: start, or go on from where it stands
#   bash studies/reference_run.sh --fast     # the candidate: the same case under the fast
#                                            # profile (`drumflow run --fast`: contact step, no
#                                            # dashpot, no conduction, the converged stop live),
#                                            # in model_two_fast/, shipped beside the reference
#   bash studies/reference_run.sh --model one [--fast]
#                                            # the same for paper model one (model_one/,
#                                            # model_one_fast/); its reference is needed to 9 s
#                                            # at least (issue 35), about 10 h of this machine
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
# `bash studies/ship_reference.sh` copies into results/bench/reference/<name>/.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
root="${DRUMFLOW_REFERENCE_ROOT:-/var/tmp/drumflow-runs/reference}"
model="two"
profile=()
while [ $# -gt 0 ]; do
  case "$1" in
    --fast) profile=(--fast) ;;
    --model)
      model="${2:-}"; shift
      case "$model" in one|two) ;; *) echo "reference_run.sh: --model ${model:-(none)}; allowed: one, two" >&2; exit 2 ;; esac ;;
    *) echo "reference_run.sh: unknown option $1; allowed: --fast, --model one|two" >&2; exit 2 ;;
  esac
  shift
done
name="model_${model}${profile:+_fast}"
run="$root/$name"
shipped="$here/results/bench/reference/$name"
mkdir -p "$root"
cd "$here"

case_file="cases/paper_model_${model}.toml"
if [ ! -f "$run/manifest.json" ]; then
  latest="$(ls "$shipped"/state_*s.npz 2>/dev/null | sort -V | tail -n 1 || true)"
  if [ -n "$latest" ]; then
    # The shipped case with the shipped state as its start (an absolute path: the case copy
    # lives outside the work tree).
    case_file="$root/${name}_from_state.toml"
    sed "s|^\[run\]|[run]\nstart_state = \"$latest\"|" "cases/paper_model_${model}.toml" > "$case_file"
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
