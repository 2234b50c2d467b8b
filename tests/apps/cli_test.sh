#!/usr/bin/env bash
# CLI tests of the libmorph apps, run by ctest one case at a time: cli_test.sh CASE.
# The binaries and folders come from the environment (tests/apps/CMakeLists.txt):
#   MESH_DILATE MESH_ERODE MESH_OPEN MESH_CLOSE MESH_MORPH  the apps
#   DATA (tests/apps/data), SAMPLES (samples/), WORK_ROOT (a scratch folder), HERE (tests/apps)
# Results are read back with mesh-morph --stats (a separate process: read, validate,
# count) and checked against analytic values; colours with face_colors.py.
set -uo pipefail

case_name=${1:?usage: cli_test.sh CASE}
for var in MESH_DILATE MESH_ERODE MESH_OPEN MESH_CLOSE MESH_MORPH DATA SAMPLES WORK_ROOT HERE; do
  [ -n "${!var:-}" ] || { echo "cli_test.sh: $var is not set" >&2; exit 2; }
done
W="$WORK_ROOT/$case_name"
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 2

fail() {
  echo "FAIL [$case_name]: $*" >&2
  exit 1
}

# run CODE COMMAND...: runs COMMAND (stdout to out.txt, stderr to err.txt), expects CODE.
run() {
  local want=$1
  shift
  "$@" >out.txt 2>err.txt
  local got=$?
  if [ "$got" -ne "$want" ]; then
    echo "--- stderr of: $*" >&2
    cat err.txt >&2
    fail "expected exit $want, got $got"
  fi
}

# expect_error PROGRAM TEXT: stderr is exactly one line "PROGRAM: error: ..." containing TEXT.
expect_error() {
  local lines
  lines=$(grep -c '' err.txt)
  [ "$lines" -eq 1 ] || { cat err.txt >&2; fail "expected one line on stderr, got $lines"; }
  grep -q "^$1: error: " err.txt || { cat err.txt >&2; fail "expected '$1: error: ' on stderr"; }
  grep -qF -- "$2" err.txt || { cat err.txt >&2; fail "expected '$2' in the error"; }
}

expect_in() {  # expect_in TEXT FILE
  grep -qF -- "$1" "$2" || { cat "$2" >&2; fail "expected '$1' in $2"; }
}

expect_absent() {  # expect_absent FILE...
  for f in "$@"; do [ ! -e "$f" ] || fail "$f should not exist"; done
}

# The last JSON line of stderr (err.txt).
stats_line() { grep '^{' err.txt | tail -n 1; }

# stats_of FILE: the --stats JSON of mesh-morph checking FILE (a separate read-back).
stats_of() {
  "$MESH_MORPH" "$1" --stats 2>&1 >/dev/null | grep '^{' | tail -n 1
}

# jget JSON KEY: one value of a JSON object ("null" for null); fails if not JSON.
jget() {
  python3 -c 'import json,sys; v=json.loads(sys.argv[1])[sys.argv[2]]; print("null" if v is None else str(v).lower() if isinstance(v,bool) else v)' "$1" "$2" ||
    fail "not JSON or no key '$2': $1"
}

expect_eq() {  # expect_eq GOT WANT WHAT
  [ "$1" == "$2" ] || fail "$3: expected $2, got $1"
}

expect_near() {  # expect_near GOT WANT WHAT [TOLERANCE]
  python3 -c 'import sys; a,b,t=float(sys.argv[1]),float(sys.argv[2]),float(sys.argv[3]); sys.exit(0 if abs(a-b)<=t else 1)' \
    "$1" "$2" "${4:-1e-9}" || fail "$3: expected $2, got $1"
}

# expect_mesh FILE VERTICES FACETS VOLUME: FILE reads back as a valid convex polyhedron
# with these counts and volume.
expect_mesh() {
  local s
  s=$(stats_of "$1")
  [ -n "$s" ] || fail "$1 does not read back as a convex polyhedron"
  expect_eq "$(jget "$s" vertices)" "$2" "$1 vertices"
  expect_eq "$(jget "$s" facets)" "$3" "$1 facets"
  expect_near "$(jget "$s" volume)" "$4" "$1 volume" 1e-9
}

# expect_empty_mesh FILE: an OFF file holding no vertex and no face.
expect_empty_mesh() {
  python3 - "$1" <<'EOF' || fail "$1 is not an empty OFF mesh"
import sys
words = [w for line in open(sys.argv[1]) for w in line.split("#", 1)[0].split()]
assert words[0] == "OFF" and words[1:3] == ["0", "0"], words[:4]
EOF
}

# no_temporaries DIR EXPECTED...: DIR holds exactly the EXPECTED names (no temporary).
only_files() {
  local dir=$1
  shift
  local listed
  listed=$(cd "$dir" && ls -A | sort)
  local wanted
  wanted=$(printf '%s\n' "$@" | sed '/^$/d' | sort)
  [ "$listed" == "$wanted" ] || fail "$dir holds [$(echo $listed)], expected [$(echo $wanted)]"
}

# op_args APP SIZE: sets OP to the arguments naming an operation by cube:SIZE for APP.
op_args() {
  if [ "$1" == "$MESH_MORPH" ]; then OP=(--op "dilate cube:$2"); else OP=(--se "cube:$2"); fi
}

APPS=("$MESH_DILATE" "$MESH_ERODE" "$MESH_OPEN" "$MESH_CLOSE" "$MESH_MORPH")
cube="$DATA/cube.off"

case "$case_name" in

  # ------------------------------------------------------------------ operations
  dilate.cube)
    # [0,1]^3 (+) cube of edge 0.2 centred on 0 = [-0.1,1.1]^3: 8 vertices, 6 facets.
    run 0 "$MESH_DILATE" "$cube" --se cube:0.2 -o out.off
    expect_mesh out.off 8 6 1.728
    ;;
  dilate.se_file)
    # An element read from a file gives the same result as the same parametric solid.
    run 0 "$MESH_DILATE" "$cube" --se "$DATA/octahedron.off" -o file.off
    run 0 "$MESH_DILATE" "$cube" --se octahedron:0.1 -o spec.off
    # cube (+) octahedron: 6 translated squares, 8 corner triangles, 12 edge rectangles;
    # volume by mixed volumes: 1 + 6r + 6r^2 + 4r^3/3.
    volume=$(python3 -c 'r=0.1; print(1 + 6*r + 6*r*r + 4*r**3/3)')
    expect_mesh file.off 24 26 "$volume"
    expect_mesh spec.off 24 26 "$volume"
    ;;
  dilate.labels_ply | dilate.labels_off)
    ext=${case_name##*_}
    run 0 "$MESH_DILATE" "$cube" --se octahedron:0.1 -o "out.$ext" --label-facets --stats
    s=$(stats_line)
    expect_eq "$(jget "$s" translated)" 6 "translated facets"
    expect_eq "$(jget "$s" corner)" 8 "corner facets"
    expect_eq "$(jget "$s" edge)" 12 "edge facets"
    colors=$(python3 "$HERE/face_colors.py" "out.$ext") || fail "cannot read the colours of out.$ext"
    expect_eq "$(python3 -c 'import json,sys; c=json.loads(sys.argv[1])["colors"]; print(c.get("0 114 178",0), c.get("230 159 0",0), c.get("0 158 115",0), sum(c.values()))' "$colors")" \
      "6 8 12 26" "facets by palette colour (translated corner edge all) in out.$ext"
    if [ "$ext" == ply ]; then
      expect_in "property uchar red" out.ply
    fi
    # Without --label-facets there is no colour.
    run 0 "$MESH_DILATE" "$cube" --se octahedron:0.1 -o "plain.$ext"
    expect_eq "$(python3 -c 'import json,sys; print(len(json.loads(sys.argv[1])["colors"]))' "$(python3 "$HERE/face_colors.py" "plain.$ext")")" \
      0 "colours without --label-facets"
    ;;
  erode.cube)
    # [0,1]^3 (-) cube of edge 0.2 = [0.1,0.9]^3.
    run 0 "$MESH_ERODE" "$cube" --se cube:0.2 -o out.off --stats
    expect_mesh out.off 8 6 0.512
    s=$(stats_line)
    expect_eq "$(jget "$s" translated)" 6 "erosion facets are A's facets moved inwards"
    ;;
  erode.empty)
    # An element larger than the input: empty result, exit 0, a warning, an empty mesh.
    run 0 "$MESH_ERODE" "$cube" --se cube:2 -o out.off --stats
    expect_in "mesh-erode: warning: " err.txt
    expect_in "empty" err.txt
    expect_empty_mesh out.off
    s=$(stats_line)
    expect_eq "$(jget "$s" empty)" true "stats empty"
    expect_eq "$(jget "$s" vertices)" 0 "stats vertices"
    # --quiet silences the warning.
    run 0 "$MESH_ERODE" "$cube" --se cube:2 -o quiet.off -q
    [ ! -s err.txt ] || fail "--quiet still printed: $(cat err.txt)"
    ;;
  erode.fail_on_empty)
    run 4 "$MESH_ERODE" "$cube" --se cube:2 -o out.off --fail-on-empty
    expect_error mesh-erode "empty"
    expect_absent out.off
    ;;
  open.cube)
    # A cube opened by a smaller cube is itself; opened by a sphere it loses its corners.
    run 0 "$MESH_OPEN" "$cube" --se cube:0.2 -o same.off
    expect_mesh same.off 8 6 1
    run 0 "$MESH_OPEN" "$cube" --se sphere:r=0.1,level=1 -o rounded.ply --stats
    s=$(stats_line)
    python3 -c 'import json,sys; s=json.loads(sys.argv[1]); assert 0.9 < s["volume"] < 1 and s["corner"] > 0 and s["edge"] > 0, s' "$s" ||
      fail "the rounded cube: $s"
    r=$(stats_of rounded.ply)
    expect_eq "$(jget "$r" facets)" "$(jget "$s" facets)" "rounded.ply facets read back"
    ;;
  close.cube)
    # Closing a convex solid gives it back.
    run 0 "$MESH_CLOSE" "$cube" --se sphere:r=0.1,level=1 -o out.obj
    expect_mesh out.obj 8 6 1
    ;;
  all.samples)
    # Every app on every sample mesh of samples/ (skipped while there is none).
    shopt -s nullglob
    samples=("$SAMPLES"/*.off "$SAMPLES"/*.ply "$SAMPLES"/*.obj "$SAMPLES"/*.stl)
    [ ${#samples[@]} -gt 0 ] || exit 77
    for sample in "${samples[@]}"; do
      "$MESH_MORPH" "$sample" -q || continue  # not every sample is meant to be an operand
      for app in "$MESH_DILATE" "$MESH_ERODE" "$MESH_OPEN" "$MESH_CLOSE"; do
        # A sphere shares symmetries with many samples (nearly coplanar and exactly
        # degenerate facet pairs); a 7-gon prism shares none.
        for se in sphere:r=0.02,level=1 cylinder:r=0.02,h=0.03,n=7; do
          out="$(basename "$app")-$(basename "${sample%.*}")-${se%%:*}.off"
          run 0 "$app" "$sample" --se "$se" -o "$out" --stats
          s=$(stats_line)
          if [ "$(jget "$s" empty)" == false ]; then
            r=$(stats_of "$out")
            expect_eq "$(jget "$r" facets)" "$(jget "$s" facets)" "$out facets read back"
          fi
        done
      done
    done
    ;;

  # ------------------------------------------------------------------ mesh-morph
  morph.check)
    run 0 "$MESH_MORPH" "$cube" -v
    expect_in "8 vertices, 12 edges, 6 facets" err.txt
    run 0 "$MESH_MORPH" "$cube"
    [ ! -s err.txt ] || fail "a silent check printed: $(cat err.txt)"
    run 3 "$MESH_MORPH" "$DATA/dart.off"
    expect_error mesh-morph "dart.off"
    ;;
  morph.convert)
    run 0 "$MESH_MORPH" "$cube" -o cube.ply --binary
    head -c 200 cube.ply | grep -q "format binary_little_endian" || fail "--binary PLY is not binary"
    run 0 "$MESH_MORPH" cube.ply -o cube.stl
    run 0 "$MESH_MORPH" cube.stl -o cube.obj
    # STL is triangles; the volume survives every conversion exactly.
    expect_mesh cube.ply 8 6 1
    expect_near "$(jget "$(stats_of cube.obj)" volume)" 1 "volume after off->ply->stl->obj"
    ;;
  morph.chain)
    run 0 "$MESH_MORPH" "$cube" -o out.off --op "erode cube:0.2" --op "dilate cube:0.2" --stats
    expect_mesh out.off 8 6 1
    s=$(stats_line)
    expect_eq "$(jget "$s" op)" "erode cube:0.2 | dilate cube:0.2" "stats op"
    ;;
  morph.empty_chain)
    # An empty result stops the chain: warning, empty mesh, exit 0 (4 with --fail-on-empty).
    run 0 "$MESH_MORPH" "$cube" -o out.off --op "erode cube:3" --op "dilate cube:1"
    expect_in "warning" err.txt
    expect_empty_mesh out.off
    run 4 "$MESH_MORPH" "$cube" -o failed.off --op "erode cube:3" --op "dilate cube:1" --fail-on-empty
    expect_absent failed.off
    ;;
  morph.pipeline_same_bytes)
    cat >steps.morph <<'EOF'
# close then open, as the --op chain below
close box:0.1,0.2,0.3   # trailing comment

   open   sphere:r=0.1,level=1
EOF
    run 0 "$MESH_MORPH" "$cube" -o pipeline.ply --pipeline steps.morph --label-facets
    run 0 "$MESH_MORPH" "$cube" -o ops.ply --op "close box:0.1,0.2,0.3" --op "open sphere:r=0.1,level=1" --label-facets
    cmp pipeline.ply ops.ply || fail "--pipeline and the same --op chain give different bytes"
    ;;
  morph.pipeline_error)
    printf 'open sphere:r=0.1\n# fine so far\nopne cube:0.1\n' >bad.morph
    run 64 "$MESH_MORPH" "$cube" -o out.off --pipeline bad.morph
    expect_error mesh-morph "bad.morph:3: unknown operation 'opne'"
    printf 'dilate sphere:r=oops\n' >badse.morph
    run 64 "$MESH_MORPH" "$cube" -o out.off --pipeline badse.morph
    expect_error mesh-morph "badse.morph:1"
    printf '# nothing\n\n' >nothing.morph
    run 64 "$MESH_MORPH" "$cube" -o out.off --pipeline nothing.morph
    expect_error mesh-morph "no step"
    run 66 "$MESH_MORPH" "$cube" -o out.off --pipeline missing.morph
    expect_error mesh-morph "missing.morph"
    run 64 "$MESH_MORPH" "$cube" -o out.off --op "erode"
    expect_error mesh-morph "--op 1"
    expect_absent out.off
    ;;
  morph.sample_pipelines)
    shopt -s nullglob
    pipelines=("$SAMPLES"/pipelines/*.morph)
    [ ${#pipelines[@]} -gt 0 ] || fail "no samples/pipelines/*.morph"
    for p in "${pipelines[@]}"; do
      name=$(basename "${p%.morph}")
      run 0 "$MESH_MORPH" "$cube" -o "$name.off" --pipeline "$p" --stats
      s=$(stats_line)
      [ "$(jget "$s" empty)" == true ] || expect_eq "$(jget "$(stats_of "$name.off")" facets)" "$(jget "$s" facets)" "$name facets"
    done
    ;;

  # ------------------------------------------------------------------ exit codes
  exit.bad_option)
    for app in "${APPS[@]}"; do
      op_args "$app" 1
      run 64 "$app" --no-such-option "$cube" "${OP[@]}" -o out.off
      expect_error "$(basename "$app")" "no-such-option"
      run 64 "$app" "$cube" "${OP[@]}" -o out.off --threads -2
      run 64 "$app" "$cube" "${OP[@]}" -o out.off --format xyz
      expect_error "$(basename "$app")" "xyz"
      run 64 "$app" "$cube" "${OP[@]}" -o out.off -q -v
    done
    run 64 "$MESH_DILATE" "$cube" -o out.off
    expect_error mesh-dilate "missing --se"
    run 64 "$MESH_DILATE" "$cube" --se cube:1
    expect_error mesh-dilate "missing -o"
    run 64 "$MESH_DILATE" --se cube:1 -o out.off
    expect_error mesh-dilate "missing INPUT"
    run 64 "$MESH_DILATE" "$cube" "$cube" --se cube:1 -o out.off
    run 64 "$MESH_DILATE" "$cube" --se cube:1 -o out.xyz
    expect_error mesh-dilate "out.xyz"
    run 64 "$MESH_MORPH" "$cube" "$cube" -o out.off
    expect_error mesh-morph "--output-dir"
    run 64 "$MESH_MORPH" "$cube" -o out.off --op "dilate cube:1" --pipeline x.morph
    expect_absent out.off out.xyz
    ;;
  exit.bad_se)
    run 64 "$MESH_DILATE" "$cube" --se sphere:r=abc -o out.off
    expect_error mesh-dilate "--se"
    expect_in "--help" err.txt
    run 64 "$MESH_ERODE" "$cube" --se pyramid:1 -o out.off
    expect_error mesh-erode "--se"
    run 66 "$MESH_DILATE" "$cube" --se missing_se.off -o out.off
    expect_error mesh-dilate "missing_se.off"
    run 3 "$MESH_DILATE" "$cube" --se "$DATA/dart.off" -o out.off
    expect_error mesh-dilate "dart.off"
    expect_absent out.off
    ;;
  exit.missing_input)
    for app in "${APPS[@]}"; do
      op_args "$app" 1
      run 66 "$app" no_such_file.off "${OP[@]}" -o out.off
      expect_error "$(basename "$app")" "no_such_file.off"
    done
    expect_absent out.off
    ;;
  exit.malformed)
    for app in "${APPS[@]}"; do
      op_args "$app" 1
      run 65 "$app" "$DATA/malformed.off" "${OP[@]}" -o out.off
      expect_error "$(basename "$app")" "malformed.off"
    done
    expect_absent out.off
    ;;
  exit.not_convex)
    for app in "${APPS[@]}"; do
      op_args "$app" 0.1
      run 3 "$app" "$DATA/dart.off" "${OP[@]}" -o out.off
      expect_error "$(basename "$app")" "dart.off"
      run 3 "$app" "$DATA/open_box.off" "${OP[@]}" -o out.off
      expect_error "$(basename "$app")" "open_box.off"
    done
    expect_absent out.off
    ;;
  exit.unwritable)
    # A path under a regular file, and a missing directory (root ignores permission bits).
    run 73 "$MESH_DILATE" "$cube" --se cube:0.2 -o /etc/hostname/out.off
    expect_error mesh-dilate "/etc/hostname/out.off"
    run 73 "$MESH_DILATE" "$cube" --se cube:0.2 -o no_such_dir/out.off
    expect_error mesh-dilate "no_such_dir/out.off"
    run 73 "$MESH_MORPH" "$cube" -o no_such_dir/out.ply
    only_files . out.txt err.txt
    # An existing output is left as it was when the write fails... and replaced when it works.
    cp "$cube" keep.off
    run 0 "$MESH_DILATE" "$cube" --se cube:0.2 -o keep.off
    expect_mesh keep.off 8 6 1.728
    ;;
  exit.inverted_note)
    run 0 "$MESH_DILATE" "$DATA/cube_inverted.off" --se cube:0.2 -o out.off -v
    expect_in "mesh-dilate: note: " err.txt
    expect_in "cube_inverted.off" err.txt
    expect_mesh out.off 8 6 1.728
    ;;

  # ------------------------------------------------------------------ stats, streams, threads
  stats.json)
    run 0 "$MESH_OPEN" "$cube" --se octahedron:0.1 -o out.ply --stats -q
    [ "$(grep -c '' err.txt)" -eq 1 ] || fail "--stats must print exactly one line: $(cat err.txt)"
    s=$(cat err.txt)
    python3 - "$s" <<'EOF' || fail "bad --stats JSON: $s"
import json, sys
s = json.loads(sys.argv[1])
keys = ["op", "input", "vertices", "edges", "facets", "translated", "corner", "edge",
        "compute_ms", "read_ms", "write_ms", "threads", "empty"]
missing = [k for k in keys if k not in s]
assert not missing, missing
assert s["op"] == "open" and s["input"].endswith("cube.off"), s
assert s["translated"] + s["corner"] + s["edge"] == s["facets"], s
assert s["vertices"] - s["edges"] + s["facets"] == 2, s   # Euler, genus 0
assert min(s["compute_ms"], s["read_ms"], s["write_ms"]) >= 0 and s["threads"] >= 1, s
EOF
    r=$(stats_of out.ply)
    for key in vertices edges facets; do
      expect_eq "$(jget "$r" "$key")" "$(jget "$s" "$key")" "$key of out.ply read back"
    done
    ;;
  stdio)
    "$MESH_DILATE" - --format off --se cube:0.2 -o - <"$cube" >out.off 2>err.txt || fail "stdin to stdout: $(cat err.txt)"
    expect_mesh out.off 8 6 1.728
    "$MESH_MORPH" - --input-format off -o - --format ply --op "erode cube:0.2" <"$cube" >out.ply 2>err.txt ||
      fail "mesh-morph stdin to stdout: $(cat err.txt)"
    expect_mesh out.ply 8 6 0.512
    run 64 "$MESH_DILATE" - --se cube:0.2 -o out2.off <"$cube"
    expect_error mesh-dilate "--input-format"
    run 64 "$MESH_DILATE" "$cube" --se cube:0.2 -o -
    expect_error mesh-dilate "--format"
    ;;
  threads)
    run 0 "$MESH_OPEN" "$cube" --se sphere:r=0.1,level=2 -o one.ply --threads 1 --stats
    expect_eq "$(jget "$(stats_line)" threads)" 1 "stats threads"
    run 0 "$MESH_OPEN" "$cube" --se sphere:r=0.1,level=2 -o two.ply --threads 2
    run 0 "$MESH_OPEN" "$cube" --se sphere:r=0.1,level=2 -o all.ply
    cmp one.ply two.ply && cmp one.ply all.ply || fail "results differ with the thread count"
    ;;
  help_version)
    for app in "${APPS[@]}"; do
      run 0 "$app" --help
      for text in "Usage:" "Exit status" "sphere:r=" "--se" "--stats" "Examples"; do expect_in "$text" out.txt; done
      run 0 "$app" --version
      expect_in "$(basename "$app") (libmorph) " out.txt
    done
    ;;

  # ------------------------------------------------------------------ batch
  batch.bad_file)
    mkdir in
    cp "$cube" in/a.off
    cp "$DATA/malformed.off" in/b.off
    cp "$DATA/cube_inverted.off" in/c.off
    cp "$DATA/dart.off" in/d.off
    run 1 "$MESH_MORPH" in --output-dir out --op "dilate cube:0.2" --report report.csv
    only_files out a.off c.off
    expect_mesh out/a.off 8 6 1.728
    expect_mesh out/c.off 8 6 1.728
    expect_in "failed: in/b.off in/d.off" err.txt
    python3 - <<'EOF' || fail "bad report: $(cat report.csv)"
import csv
rows = list(csv.DictReader(open("report.csv")))
assert [r["file"] for r in rows] == ["in/a.off", "in/b.off", "in/c.off", "in/d.off"], rows
assert [r["status"] for r in rows] == ["ok", "failed", "ok", "failed"], rows
assert rows[0]["vertices"] == "8" and rows[0]["facets"] == "6", rows[0]
assert "b.off" in rows[1]["message"] or rows[1]["message"], rows[1]
assert float(rows[2]["compute_ms"]) >= 0, rows[2]
EOF
    # A list file with a missing entry, --format choosing the extension.
    printf '# inputs\n%s\nnot_there.off\n\n%s\n' "in/a.off" "in/c.off" >list.txt
    run 1 "$MESH_MORPH" --list list.txt --output-dir out2 --format ply -q
    only_files out2 a.ply c.ply
    expect_in "not_there.off" err.txt
    # Two inputs writing the same output, or an output replacing an input, is refused
    # before any work.
    cp "$cube" in/a.ply
    run 64 "$MESH_MORPH" in/a.off in/a.ply --output-dir out3 --format off
    expect_error mesh-morph "would both be written"
    run 64 "$MESH_MORPH" in/a.off --output-dir in
    expect_error mesh-morph "would overwrite the input"
    expect_absent out3
    ;;
  batch.check)
    # A batch with no --output-dir checks every file and writes nothing.
    run 1 "$MESH_MORPH" "$cube" "$DATA/dart.off" "$DATA/octahedron.off"
    expect_in "failed: $DATA/dart.off" err.txt
    run 0 "$MESH_MORPH" "$cube" "$DATA/octahedron.off" -q
    ;;
  batch.sigint)
    # Many slow inputs; SIGINT in the middle: exit 130, finished outputs intact, no temporary.
    mkdir in
    for i in $(seq -w 1 60); do cp "$cube" "in/m$i.off"; done
    # About 0.3 s per file on one thread: the whole batch would take ~20 s.
    "$MESH_MORPH" in --output-dir out --op "dilate sphere:r=0.1,level=5" --threads 1 --report report.csv \
      >out.txt 2>err.txt &
    pid=$!
    for _ in $(seq 1 100); do  # wait for the first finished file (at most 10 s)
      [ -n "$(ls out 2>/dev/null | grep -v '^\.')" ] && break
      sleep 0.1
    done
    kill -INT "$pid"
    wait "$pid"
    code=$?
    [ "$code" -eq 130 ] || { cat err.txt >&2; fail "expected exit 130 after SIGINT, got $code"; }
    expect_in "interrupted" err.txt
    finished=$(ls out | grep -c '')
    [ "$finished" -ge 1 ] && [ "$finished" -lt 60 ] || fail "$finished outputs after SIGINT"
    hidden=$(ls -A out | grep '^\.' || true)
    [ -z "$hidden" ] || fail "temporary files left: $hidden"
    for f in out/*.off; do stats_of "$f" | grep -q '"vertices"' || fail "$f is not a complete mesh"; done
    grep -q ',skipped,' report.csv || fail "the report lists no skipped input"
    ;;

  sigint.single)
    # A single-file app interrupted while computing exits 130 at once and writes nothing.
    # --verbose notes the element once it is built, after the handler is installed and before
    # the sum (about 0.3 s on one thread): the signal is sent then, not after a fixed sleep that
    # a loaded machine can spend still loading the program (the default action would kill it
    # without the message).
    "$MESH_DILATE" "$cube" --se sphere:r=0.1,level=7 -o out.off --threads 1 --verbose \
      >out.txt 2>err.txt &
    pid=$!
    for _ in $(seq 1 200); do  # at most 10 s
      grep -q "structuring element" err.txt 2>/dev/null && break
      sleep 0.05
    done
    kill -INT "$pid"
    wait "$pid"
    code=$?
    [ "$code" -eq 130 ] || { cat err.txt >&2; fail "expected exit 130 after SIGINT, got $code"; }
    expect_in "mesh-dilate: interrupted" err.txt
    only_files . out.txt err.txt
    ;;

  *)
    echo "cli_test.sh: unknown case '$case_name'" >&2
    exit 2
    ;;
esac
exit 0
