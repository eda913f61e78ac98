#!/usr/bin/env bash
# CLI round trip of the distance subcommands through the real levelsetd binary:
# cpt (mesh -> band, with closest points) -> info -> sample -> redistance (both methods) -> info,
# plus their error paths. Args: LEVELSETD SCRATCH_DIR CGAL_DATA_DIR
set -euo pipefail
bin=$1; dir=$2; data=$3
rm -rf "$dir"; mkdir -p "$dir"
checks=0
pass() { checks=$((checks + 1)); }
fail() { echo "cli_distance: FAILED: $*" >&2; exit 1; }
py=/usr/bin/python3

# A closed box mesh we know the answer for: [0,2]x[0,1]x[0,1].
cat > "$dir/box.off" <<'MESH'
OFF
8 12 0
0 0 0
2 0 0
0 1 0
2 1 0
0 0 1
2 0 1
0 1 1
2 1 1
3 0 2 3
3 0 3 1
3 4 5 7
3 4 7 6
3 0 1 5
3 0 5 4
3 2 6 7
3 2 7 3
3 0 4 6
3 0 6 2
3 1 3 7
3 1 7 5
MESH
"$bin" cpt "$dir/box.off" --resolution 64 --band 3 --closest-points -o "$dir/box.lsg" \
  --stats "$dir/cpt.json" > /dev/null || fail "cpt box"
pass
"$py" - "$dir/cpt.json" <<'PY' || fail "cpt stats"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["op"] == "cpt" and s["active_voxels"] > 1000 and s["triangles"] == 12, s
assert all(k in s["seconds"] for k in ("total", "distance", "sign")), s
assert s["closest_points"] is True
PY
pass
"$bin" info "$dir/box.lsg" --json > "$dir/info.json" || fail "info box.lsg"
"$py" - "$dir/info.json" "$dir/cpt.json" <<'PY' || fail "info vs stats"
import json, sys
i, s = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert i["kind"] == "narrow_band" and i["active_voxels"] == s["active_voxels"], (i, s)
assert i["closest_points"] is True, i
PY
pass

# Sample at known points: centre (inside, beyond the band), on a face, just outside a face.
printf '1 0.5 0.5\n0 0.5 0.5\n2.01 0.5 0.5\n100 100 100\n' > "$dir/points.xyz"
"$bin" sample "$dir/box.lsg" --points "$dir/points.xyz" -o "$dir/values.txt" > /dev/null || fail "sample"
"$py" - "$dir/values.txt" "$dir/info.json" <<'PY' || fail "sampled values"
import sys, json
v = [float(x) for x in open(sys.argv[1]).read().split()]
bg = json.load(open(sys.argv[2]))["band_half_width"]
assert len(v) == 4, v
assert abs(v[0] + bg) < 1e-6, v          # deep inside: -band limit
assert abs(v[1]) < 1e-6, v               # on the face
assert abs(v[2] - 0.01) < 1e-4, v        # 0.01 outside the face
assert abs(v[3] - bg) < 1e-6, v          # far away: +band limit
PY
pass
"$bin" sample "$dir/box.lsg" --points "$dir/points.xyz" | grep -qv nan || fail "sample to stdout"
pass

for method in sweep march; do
  "$bin" redistance "$dir/box.lsg" --method "$method" --band 5 -o "$dir/r_$method.lsg" \
    --stats "$dir/r_$method.json" > /dev/null || fail "redistance $method"
  "$py" - "$dir/r_$method.json" "$method" <<'PY' || fail "redistance stats"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["op"] == "redistance" and s["band_half_width"] == 5 and s["active_voxels"] > 0, s
# The method's own count of passes over the bricks: iterations for the sweep, rounds for the march.
counts = (s["sweep_iterations"], s["march_rounds"])
assert (counts[0] >= 1 and counts[1] == 0) if sys.argv[2] == "sweep" else (counts[0] == 0 and counts[1] >= 1), s
PY
  pass
done

# Surface of the box: area 10, volume 2 (marching cubes cuts the sharp edges a little).
for method in mc nets; do
  "$bin" measure "$dir/box.lsg" --method "$method" --json > "$dir/measure_$method.json" || fail "measure $method"
  "$py" - "$dir/measure_$method.json" <<'PY' || fail "measure values"
import json, sys
m = json.load(open(sys.argv[1]))
assert m["watertight"] and m["manifold"] and m["components"] == 1 and m["genus"] == 0, m
assert abs(m["area"] - 10) < 0.2 and abs(m["volume"] - 2) < 0.04, m
PY
  "$bin" mesh "$dir/box.lsg" --method "$method" -o "$dir/box_$method.ply" > /dev/null || fail "mesh $method"
  "$bin" info "$dir/box_$method.ply" --json > "$dir/mesh_$method.json" || fail "info of the mesh"
  "$py" - "$dir/mesh_$method.json" "$dir/measure_$method.json" <<'PY' || fail "mesh file"
import json, sys
i, m = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert i["kind"] == "mesh" and i["triangles"] == m["triangles"] and i["vertices"] == m["vertices"], (i, m)
PY
  pass
done

if [ -f "$data/meshes/knot.off" ]; then
  "$bin" cpt "$data/meshes/knot.off" --resolution 96 --band 3 -o "$dir/knot.lsg" --threads 1 > /dev/null \
    || fail "cpt knot.off"
  "$bin" cpt "$data/meshes/knot.off" --resolution 96 --band 3 -o "$dir/knot2.lsg" --threads 2 > /dev/null \
    || fail "cpt knot.off 2 threads"
  cmp -s "$dir/knot.lsg" "$dir/knot2.lsg" || fail "1 and 2 threads give different files"
  pass
  # Both distance methods (characteristic polyhedra, each triangle's slab) give the same band;
  # the stats say which ran; an unknown method is refused naming the choices.
  for m in characteristic slab; do
    "$bin" cpt "$data/meshes/knot.off" --resolution 96 --band 6 --method "$m" -o "$dir/knot_$m.lsg" \
      --stats "$dir/knot_$m.json" > /dev/null || fail "cpt --method $m"
  done
  "$py" - "$dir/knot_characteristic.json" "$dir/knot_slab.json" <<'PY' || fail "cpt methods disagree"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["method"] == "characteristic" and b["method"] == "slab", (a["method"], b["method"])
assert a["active_voxels"] == b["active_voxels"] > 10000, (a["active_voxels"], b["active_voxels"])
assert a["distance_evaluations"] < 3 * a["active_voxels"], a["distance_evaluations"]
PY
  pass
  if "$bin" cpt "$data/meshes/knot.off" --method fast -o "$dir/bad.lsg" 2> "$dir/bad_method.err" > /dev/null; then
    fail "cpt --method fast accepted"
  fi
  grep -q "characteristic" "$dir/bad_method.err" || fail "cpt --method fast: $(cat "$dir/bad_method.err")"
  [ -e "$dir/bad.lsg" ] && fail "cpt --method fast wrote its output"
  pass
fi

# An open mesh (issue 14): CGAL's cube without its top face. The band closes the hole across
# the opening (where the winding number crosses 1/2), so measure reports the closed cube; the
# result does not depend on the thread count.
if [ -f "$data/meshes/cube-ouvert.off" ]; then
  "$bin" cpt "$data/meshes/cube-ouvert.off" --resolution 96 -o "$dir/ouvert.lsg" --threads 1 \
    --stats "$dir/ouvert_cpt.json" > "$dir/ouvert_summary.txt" || fail "cpt cube-ouvert.off"
  grep -q "open mesh (4 open edges): holes closed across" "$dir/ouvert_summary.txt" \
    || fail "cpt summary: $(cat "$dir/ouvert_summary.txt")"
  "$bin" cpt "$data/meshes/cube-ouvert.off" --resolution 96 -o "$dir/ouvert2.lsg" --threads 2 > /dev/null \
    || fail "cpt cube-ouvert.off 2 threads"
  cmp -s "$dir/ouvert.lsg" "$dir/ouvert2.lsg" || fail "open mesh: 1 and 2 threads give different files"
  "$bin" measure "$dir/ouvert.lsg" > "$dir/ouvert_measure.txt" || fail "measure cube-ouvert"
  grep -q "watertight and manifold" "$dir/ouvert_measure.txt" || fail "open cube: $(cat "$dir/ouvert_measure.txt")"
  grep -q "euler / genus:   2 / 0$" "$dir/ouvert_measure.txt" || fail "open cube genus: $(cat "$dir/ouvert_measure.txt")"
  "$bin" measure "$dir/ouvert.lsg" --json > "$dir/ouvert_measure.json" || fail "measure cube-ouvert --json"
  "$py" - "$dir/ouvert_measure.json" "$dir/ouvert_cpt.json" <<'PY' || fail "open cube measures"
import json, sys
m, s = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert m["watertight"] and m["manifold"] and m["genus"] == 0 and m["components"] == 1, m
assert m["boundary_edges"] == 0, m
assert abs(m["volume"] - 8.0) < 0.05, m  # the closed cube [-1, 1]^3
assert m["bounds"]["max"][1] < 1.01, m    # the lid is flat: w = 1/2 on the opening's plane
assert s["open_edges"] == 4 and s["membrane_voxels"] > 1000 and s["membrane_voxels_added"] > 0, s
assert "membrane" in s["seconds"], s
PY
  pass
fi

# Error paths: one line 'levelsetd: ...' on stderr, non-zero exit, no signal.
expect_error() {
  local what=$1 pattern=$2; shift 2
  set +e
  "$@" > /dev/null 2> "$dir/err.txt"
  local rc=$?
  set -e
  [ "$rc" -ne 0 ] && [ "$rc" -lt 128 ] || fail "$what: exit code $rc"
  grep -q "^levelsetd: .*$pattern" "$dir/err.txt" || fail "$what: stderr was: $(cat "$dir/err.txt")"
  pass
}
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n' > "$dir/nan.off"
expect_error "NaN vertex" "non_finite" "$bin" cpt "$dir/nan.off" -r 32 -o "$dir/x.lsg"
printf 'OFF\n0 0 0\n' > "$dir/empty.off"
expect_error "empty mesh" "no" "$bin" cpt "$dir/empty.off" -r 32 -o "$dir/x.lsg"
expect_error "voxel budget" "voxel budget" "$bin" cpt "$dir/box.off" --voxel-size 1e-7 -o "$dir/x.lsg"
expect_error "both resolution and voxel size" "usage" "$bin" cpt "$dir/box.off" -r 32 --voxel-size 0.1 -o "$dir/x.lsg"
expect_error "bad method" "usage" "$bin" redistance "$dir/box.lsg" --method magic -o "$dir/x.lsg"
expect_error "bad order" "usage" "$bin" redistance "$dir/box.lsg" --order 3 -o "$dir/x.lsg"
expect_error "iso outside the band" "iso" "$bin" mesh "$dir/box.lsg" --iso 5 -o "$dir/x.ply"
expect_error "unknown mesh format" "file name for a mesh" "$bin" mesh "$dir/box.lsg" -o "$dir/x.xyz"
printf '1 2\n' > "$dir/bad.xyz"
expect_error "bad points" "parse_error" "$bin" sample "$dir/box.lsg" --points "$dir/bad.xyz"
[ ! -e "$dir/x.lsg" ] && [ ! -e "$dir/x.ply" ] && [ ! -e "$dir/x.xyz" ] || fail "a failed command left an output file"
pass

# A 3D image: CGAL's skull (64^3 float INR with anisotropic voxels); a truncated copy fails.
"$bin" info "$data/images/skull_2.9.inr" --json > "$dir/skull.json" || fail "info on an INR image"
/usr/bin/python3 - "$dir/skull.json" <<'PY' || fail "skull image info"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["kind"] == "image" and j["format"] == "inr" and j["dims"] == [64, 64, 64], j
assert abs(j["spacing"][0] - 3.94305) < 1e-5 and abs(j["spacing"][2] - 3.65079) < 1e-5, j
assert 5 < j["range"][1] < 6, j
PY
head -c 100000 "$data/images/skull_2.9.inr" > "$dir/cut.inr"
expect_error "truncated image" "truncated" "$bin" info "$dir/cut.inr"
pass

echo "cli_distance: $checks checks passed"
