#!/usr/bin/env bash
# The viewer's benchmark (docs/performance.md, "Viewer"): what a frame costs while the camera
# orbits, and what the viewer costs at rest, each beside `mirador render` of the same scene at the
# size of the viewer's 3D view with `raster.flat_colour=true` (the floor: a frame that draws the
# geometry and nothing else), measured in the same run, so the figures are ratios that hold across
# machines.
#
#     bash benches/viewer.sh [SCENE]        # default: the showcase, every technique on
#
# Needs Xvfb (`xvfb-run`) and what Mirador needs. Takes about two minutes after the build. The
# window is 1280×720; with the side panel open the 3D view is 950×720.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-assets/scenes/showcase.toml}
window=1280x720
view=(--width 950 --height 720)
runs=3

cargo build --release --locked --bin mirador
target=$(cargo metadata --format-version 1 --no-deps | sed -e 's/.*"target_directory":"\([^"]*\)".*/\1/')
mirador="$target/release/mirador"
xvfb=(xvfb-run -a -s "-screen 0 1920x1080x24")
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# The floor: the second frame of `render --stats` (the first pays for pipeline compilation),
# the median of a few runs.
flat() {
    for _ in $(seq "$runs"); do
        "$mirador" render "$scene" "${view[@]}" --set raster.flat_colour=true --stats -o /tmp/mirador-bench-flat.png |
            sed -n -e 's/^ *frame: *\([0-9.]*\) ms.*/\1/p'
    done | median
}
floor_ms=$(flat)
echo "render, flat colour, 950×720: $floor_ms ms (median of $runs)"

# Orbiting: 60 frames of `orbit 4 0` after 10 of warm-up, with the frame budget's default target
# (30 fps) and every technique the scene turns on. `--stats` prints the means from `measure` on.
orbit() {
    local steps=()
    for _ in $(seq 10); do steps+=(--step "orbit 4 0"); done
    steps+=(--step measure)
    for _ in $(seq 60); do steps+=(--step "orbit 4 0"); done
    "${xvfb[@]}" "$mirador" view "$scene" --size "$window" --frames 1 --stats "${steps[@]}" "$@"
}
echo
echo "orbiting (60 frames of orbit 4 0):"
orbit | grep -E "^(frames|frame:|frames apart|UI build|raster|render scale)" | tee /tmp/mirador-bench-orbit.txt
orbit_ms=$(sed -n -e 's/^frame: \([0-9.]*\) ms.*/\1/p' /tmp/mirador-bench-orbit.txt)
echo "orbit frame / flat render frame: $(awk -v a="$orbit_ms" -v b="$floor_ms" 'BEGIN { printf "%.2f", a / b }')"

# At rest: the viewer opened on the scene and left alone; its CPU time (user + system, from
# /proc) over 10 s, after 20 s for it to settle.
echo
echo "at rest:"
rest_log=$(mktemp)
"${xvfb[@]}" "$mirador" view "$scene" --size "$window" >"$rest_log" 2>&1 &
runner=$!
sleep 20
pid=$(pgrep -n -f "release/mirador view $scene" || true)
if [ -z "$pid" ]; then
    echo "the viewer did not start:"; cat "$rest_log"; exit 1
fi
ticks() { awk '{ print $14 + $15 }' "/proc/$pid/stat"; }
hz=$(getconf CLK_TCK)
before=$(ticks)
sleep 10
after=$(ticks)
kill "$pid"
wait "$runner" 2>/dev/null || true
rm -f "$rest_log"
awk -v t=$((after - before)) -v hz="$hz" -v f="$floor_ms" 'BEGIN {
    cpu = t / hz / 10
    printf "CPU over 10 s: %.1f %% of a core (%.0f ms a second, %.2f flat frames a second)\n", 100 * cpu, 1000 * cpu, 1000 * cpu / f
}'
