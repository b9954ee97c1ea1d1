#!/usr/bin/env bash
# The measurements of bench/large_shells.md: the whole Scordelis–Lo roof (scordelis_lo_whole.yaml)
# at the given knots_per_span (degree 3: 3 (k + 4)² unknowns) with the given linear solvers,
# linear or nonlinear (5× the self-weight in two load steps), one `isoflex run` each under
# /usr/bin/time: wall time and peak memory of the process, the static solve's wall time, the
# Krylov iterations (CG; FGMRES, or the direct saddle-point solver's GMRES, on a model with
# multiplier rows), the probe's displacement. Sequential; --max-memory 60G lets the estimate
# pass. A fourth argument names another model of this directory with the same keys
# (scordelis_lo_quarter.yaml: symmetry rows; scordelis_lo_two_patch.yaml: AF-BS coupling rows;
# scordelis_lo_bending_strip.yaml: the two patches with a bending strip;
# pinched_cylinder.yaml: the one-eighth pinched cylinder, symmetry rows, linear only).
# The printed value is the displacement component of a probe: the model's line
# `# measure: probe NAME COMPONENT` (pinched_cylinder.yaml: `ref z`, u_z under the load), else
# `free_edge y` (the roofs' u_y at the midpoint of the free edge). The nonlinear variant scales
# the roofs' self-weight (-90*t → -450*t); a model without it stops with a message.
# SET="KEY=VALUE …" passes each as --set KEY=VALUE (e.g. SET=solver.multigrid_coarsening=degree).
# RANKS=N (N > 1) runs each case on N MPI ranks (mpirun -n N --oversubscribe; docs/theory/
# solvers.md §6): the process time is mpirun's, the peak memory the largest of the ranks' (each
# rank under its own /usr/bin/time), and the rank column says N.
#   bench/large_shells/measure.sh "100 180 313" "direct cg_multigrid" linear
#   bench/large_shells/measure.sh "180 313" "direct cg_multigrid" linear scordelis_lo_quarter.yaml
#   RANKS=2 bench/large_shells/measure.sh "180 313" "cg_multigrid" linear
#   bench/large_shells/measure.sh "180 313" "direct cg_multigrid" linear pinched_cylinder.yaml
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
ranks=${RANKS:-1}
sets=()
for kv in ${SET:-}; do sets+=(--set "$kv"); done
read -r probe component < <(sed -n 's/^# measure: probe //p' "$here/$model"; echo free_edge y)
if [[ $kind == nonlinear ]] && ! grep -q -- '-90\*t' "$here/$model"; then
  echo "measure.sh: $model has no self-weight -90*t to scale: linear only" >&2
  exit 2
fi
mkdir -p "$work"
printf "%-8s %-13s %-9s %5s %9s %9s %9s %6s %7s %s\n" k solver kind ranks unknowns process_s solve_s CG \
  peak_GB "u_$component"
for k in $sizes; do
  for s in $solvers; do
    f="$work/${tag}_${k}_${s}_${kind}.yaml"
    sed "s/linear_solver: cg_multigrid/linear_solver: $s/; s/knots_per_span: \[40, 40\]/knots_per_span: [$k, $k]/" \
      "$here/$model" > "$f"
    if [[ $kind == nonlinear ]]; then
      sed -i 's/  linear: true/  linear: false/; s/  dt: 1$/  dt: 0.5/; s/-90\*t/-450*t/' "$f"
    fi
    out="$work/${tag}_${k}_${s}_${kind}"
    [[ $ranks -gt 1 ]] && out="${out}_${ranks}ranks"
    if [[ $ranks -gt 1 ]]; then
      rm -f "$out".time.*
      /usr/bin/time -f "%e %M" -o "$out.time" env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
        mpirun --oversubscribe -n "$ranks" sh -c '/usr/bin/time -f "%e %M" -o "$0.time.$OMPI_COMM_WORLD_RANK" "$@"' \
        "$out" "$bin" run --max-memory 60G "$f" -o "$out" "${sets[@]}" > "$out.log" 2>&1 || true
      read -r wall _ < "$out.time"
      kb=$(cat "$out".time.* | awk '$2 > m {m = $2} END {print m}')
    else
      /usr/bin/time -f "%e %M" -o "$out.time" "$bin" run --max-memory 60G "$f" -o "$out" "${sets[@]}" > "$out.log" 2>&1 || true
      read -r wall kb < "$out.time"
    fi
    python3 - "$out/summary.json" "$k" "$s" "$kind" "$wall" "$kb" "$ranks" "$probe" "$component" <<'PY'
import json, sys
path, k, s, kind, wall, kb, ranks, probe, component = sys.argv[1:]
try:
    d = json.load(open(path))
except Exception:
    print(f"{k:<8} {s:<13} {kind:<9} failed (see the .log)"); sys.exit()
u = d["probes"][probe]["displacement"]["xyz".index(component)]
print(f"{k:<8} {s:<13} {kind:<9} {ranks:>5} {d['n_unknowns']:9d} {float(wall):9.1f} {d['wall_time_s']:9.1f} "
      f"{d.get('krylov_iterations_total', 0):6d} {int(kb)/2**20:7.2f} {u:.10g}")
PY
  done
done
