#!/usr/bin/env bash
# A class graded on one machine, as a teacher would run it (docs/course/labs.md, "Grading a
# class"): N submissions of a lab, made from its answer key, its stub, its known mistakes and a
# file that does not compile in turn, each checked by `mirador lab check --lab` with JOBS checks
# at once, then `mirador lab summary` over the class. Prints the wall time and the throughput.
#
#   bash benches/class_run.sh [LAB] [N] [JOBS] [MIRADOR]
#
# defaults: transparency, 300 submissions, one check per core, target/release/mirador.
set -euo pipefail
lab="${1:-transparency}"
count="${2:-300}"
jobs="${3:-$(nproc)}"
mirador="${4:-target/release/mirador}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

"$mirador" lab new "$lab" "$work/key" --solution >/dev/null
"$mirador" lab new "$lab" "$work/stub" >/dev/null
file="$(basename "$(ls "$work"/stub/*.wgsl)")"

# The kinds of submission, in turn: the key, the stub, each known mistake, a syntax error.
kinds=("$work/key/$file" "$work/stub/$file")
python3 - "$lab" "$work" "$file" <<'EOF'
import sys, tomllib, pathlib
lab, work, file = sys.argv[1], pathlib.Path(sys.argv[2]), sys.argv[3]
spec = tomllib.loads(pathlib.Path(f"assets/labs/{lab}/lab.toml").read_text())
key = (work / "key" / file).read_text()
for i, mistake in enumerate(spec.get("mistakes", [])):
    text = key
    for old, new in mistake["replace"]:
        text = text.replace(old, new, 1)
    (work / f"mistake-{i}.wgsl").write_text(text)
(work / "broken.wgsl").write_text(key.replace("return", "retrun", 1))
EOF
for extra in "$work"/mistake-*.wgsl "$work/broken.wgsl"; do kinds+=("$extra"); done

for i in $(seq 1 "$count"); do
    dir="$work/class/student-$(printf %03d "$i")"
    mkdir -p "$dir"
    cp "${kinds[$(( (i - 1) % ${#kinds[@]} ))]}" "$dir/$file"
done

start=$(date +%s.%N)
ls -d "$work"/class/student-* | xargs -P "$jobs" -I{} \
    sh -c '"$1" lab check "$2" --lab "$3" >/dev/null 2>&1; [ $? -le 2 ]' _ "$mirador" {} "$lab"
end=$(date +%s.%N)
"$mirador" lab summary "$work/class" --out "$work/summary" >/dev/null
graded=$(ls "$work"/class/*/results.json | wc -l)
python3 - "$start" "$end" "$graded" "$count" "$jobs" "$lab" <<'EOF'
import sys
start, end, graded, count, jobs, lab = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
seconds = end - start
print(f"lab {lab}: {graded} of {count} submissions graded in {seconds:.1f} s with {jobs} at once: "
      f"{graded / seconds * 60:.0f} a minute, {seconds / graded:.2f} s each")
EOF
cp "$work/summary/summary.md" "${SUMMARY_OUT:-/dev/null}" 2>/dev/null || true
