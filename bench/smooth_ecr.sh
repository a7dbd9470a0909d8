#!/usr/bin/env bash
# The ECR 2015 table of docs/optimization.md: `isohex smooth --untangle` on each ECR input with
# the boundary fixed and sliding, beside the quality of ECR's own `_out` mesh.
# Usage: bench/smooth_ecr.sh ISOHEX_BINARY DATA_DIR OUT_DIR [THREADS]
# (e.g. bench/smooth_ecr.sh build/bin/isohex ../shared/data/hexmeshes /tmp/ecr 2)
set -euo pipefail
cli=$1 data=$2 out=$3 threads=${4:-2}
mkdir -p "$out"
# Wall time is what the JSON reports; the CPU time (user + system, from /usr/bin/time) is
# given too because on a shared machine the wall time mostly measures the other jobs.
run() {  # run LOG CPUFILE ARGS...
  local log=$1 cpu=$2
  shift 2
  /usr/bin/time -f "%U %S" -o "$cpu" "$@" >"$log" || true
}
row() {  # JSON report, CPU file -> "min / mean, #<0.2 (inverted), wall (CPU)"
  /usr/bin/python3 - "$1" "$2" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
cpu = sum(float(x) for x in open(sys.argv[2]).read().split()[-2:])
q = r["after"]
u = r.get("untangle", {})
extra = f", {len(u['given_up'])} given up" if u.get("given_up") else ""
print(f"{q['min']:.3f} / {q['mean']:.3f}, {q['below_0.2']} ({q['inverted']} inv.{extra}), {r['seconds']:.1f} s ({cpu:.1f} s CPU)")
PY
}
echo "| mesh | hexes | fixed: min / mean, #<0.2 (inverted), wall (CPU) | slide: min / mean, #<0.2 (inverted), wall (CPU) | ECR _out: min / mean, #<0.2 |"
echo "|---|---|---|---|---|"
for name in block bust dragon armadillo; do
  in="$data/ecr2015_${name}_in.mesh"
  run "$out/${name}_fixed.log" "$out/${name}_fixed.cpu" \
    "$cli" smooth "$in" -o "$out/${name}_fixed.vtk" --untangle --threads "$threads" --json "$out/${name}_fixed.json"
  run "$out/${name}_slide.log" "$out/${name}_slide.cpu" \
    "$cli" smooth "$in" -o "$out/${name}_slide.vtk" --untangle --boundary slide --threads "$threads" \
    --json "$out/${name}_slide.json"
  "$cli" quality "$data/ecr2015_${name}_out.mesh" --json "$out/${name}_out.json" >/dev/null
  ecr=$(/usr/bin/python3 -c "
import json
s = json.load(open('$out/${name}_out.json'))['metrics']['scaled_jacobian']
print(f\"{s['min']:.3f} / {s['mean']:.3f}, {s['inverted'] + s['questionable'] + s['degenerate']}\")")
  hexes=$(/usr/bin/python3 -c "import json; print(json.load(open('$out/${name}_fixed.json'))['hexes'])")
  echo "| ${name}_in | $hexes | $(row "$out/${name}_fixed.json" "$out/${name}_fixed.cpu") | $(row "$out/${name}_slide.json" "$out/${name}_slide.cpu") | $ecr |"
done
