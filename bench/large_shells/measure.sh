#!/usr/bin/env bash
# The measurements of bench/large_shells.md: the whole Scordelis–Lo roof (scordelis_lo_whole.yaml)
# at the given knots_per_span (degree 3: 3 (k + 4)² unknowns) with the given linear solvers,
# linear or nonlinear (5× the self-weight in two load steps), one `isoflex run` each under
# /usr/bin/time: wall time and peak memory of the process, the static solve's wall time, the
# Krylov iterations (CG; FGMRES, or the direct saddle-point solver's GMRES, on a model with
# multiplier rows), the free edge's displacement. Sequential; --max-memory 60G lets the estimate
# pass. A fourth argument names another model of this directory with the same keys
# (scordelis_lo_quarter.yaml: symmetry rows; scordelis_lo_two_patch.yaml: AF-BS coupling rows).
#   bench/large_shells/measure.sh "100 180 313" "direct cg_multigrid" linear
#   bench/large_shells/measure.sh "180 313" "direct cg_multigrid" linear scordelis_lo_quarter.yaml
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
sizes=${1:-"100 180"}
solvers=${2:-"direct cg_multigrid"}
kind=${3:-linear}
model=${4:-scordelis_lo_whole.yaml}
tag=$(basename "$model" .yaml)
bin=${ISOFLEX:-$root/build/isoflex}
work=${WORK:-$root/out/large_shells}
mkdir -p "$work"
printf "%-8s %-13s %-9s %9s %9s %9s %6s %7s %s\n" k solver kind unknowns process_s solve_s CG peak_GB u_y
for k in $sizes; do
  for s in $solvers; do
    f="$work/${tag}_${k}_${s}_${kind}.yaml"
    sed "s/linear_solver: cg_multigrid/linear_solver: $s/; s/knots_per_span: \[40, 40\]/knots_per_span: [$k, $k]/" \
      "$here/$model" > "$f"
    if [[ $kind == nonlinear ]]; then
      sed -i 's/  linear: true/  linear: false/; s/  dt: 1$/  dt: 0.5/; s/-90\*t/-450*t/' "$f"
    fi
    out="$work/${tag}_${k}_${s}_${kind}"
    /usr/bin/time -f "%e %M" -o "$out.time" "$bin" run --max-memory 60G "$f" -o "$out" > "$out.log" 2>&1 || true
    read -r wall kb < "$out.time"
    python3 - "$out/summary.json" "$k" "$s" "$kind" "$wall" "$kb" <<'PY'
import json, sys
path, k, s, kind, wall, kb = sys.argv[1:]
try:
    d = json.load(open(path))
except Exception:
    print(f"{k:<8} {s:<13} {kind:<9} failed (see the .log)"); sys.exit()
u = d["probes"]["free_edge"]["displacement"][1]
print(f"{k:<8} {s:<13} {kind:<9} {d['n_unknowns']:9d} {float(wall):9.1f} {d['wall_time_s']:9.1f} "
      f"{d.get('krylov_iterations_total', 0):6d} {int(kb)/2**20:7.2f} {u:.10f}")
PY
  done
done
