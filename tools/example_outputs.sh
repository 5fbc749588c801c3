#!/usr/bin/env bash
# Writes every output interpatch makes of every example into OUT (build in all four
# formats, mesh in all six, eval, info, view, demo), so that two builds of interpatch
# can be compared byte for byte: tools/example_outputs.sh BIN OUT, then diff -r.
set -euo pipefail
bin=$(realpath "$1"); out=$2
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"; out=$(realpath "$out")
cd "$here/examples"
# A command that refuses (no exact form, say) is an output too: its message and status.
run() { local tag=$1; shift; local rc=0; "$@" > /dev/null 2> "$out/$tag.stderr" || rc=$?; echo "$rc" > "$out/$tag.status"; }
for spec in *.json; do
  name=${spec%.json}
  for ext in json npz step igs; do run "$name.build.$ext" "$bin" build "$spec" -o "$out/$name.build.$ext"; done
  kind=$("$bin" info "$spec" | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["kind"])')
  if [ "$kind" = curve ]; then exts="vtk xyz"; elif [ "$kind" = volume ]; then exts="vtk vts xyz"; else exts="obj stl ply vtk vts xyz"; fi
  for ext in $exts; do run "$name.mesh.$ext" "$bin" mesh "$spec" -o "$out/$name.mesh.$ext"; done
  for ext in npy csv; do run "$name.eval.$ext" "$bin" eval "$spec" --grid 9 -o "$out/$name.eval.$ext"; done
  run "$name.info" "$bin" info "$spec" -o "$out/$name.info.json"
  run "$name.view" "$bin" view "$spec" -o "$out/$name.view.html"
done
run twisted_strip_csv "$bin" build twisted_strip.csv --shape 9x5 -o "$out/twisted_strip_csv.build.json"
run demo "$bin" demo -o "$out/demo"
# STEP and IGES headers carry the time of writing, and info the time taken;
# everything else must be equal.
find "$out" \( -name '*.step' -o -name '*.igs' \) -exec sed -i -E \
  -e 's/[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}/TIME/' -e 's/15H[0-9]{8}\.[0-9]{6}/15HTIME............/g' {} +
find "$out" \( -name '*.json' -o -name '*.html' \) -exec sed -i -E 's/"([a-z_]+_ms)": ?[-0-9.e+]+/"\1": MS/g' {} +
echo "wrote $(find "$out" -type f | wc -l) files to $out"
