#!/usr/bin/env bash
# Times the page: `bash web/time.sh [DIST] [RUNS] [webgpu|webgl2] [no-workers]` loads
# DIST/index.html?test (with `no-workers`: `&workers=0`, the page's thread traces alone) (default
# web/dist, built by web/build.sh) RUNS times (default 3) in Chromium with WebGPU on SwiftShader
# under Xvfb (with `webgl2`: without WebGPU, so the page draws with WebGL2),
# each time with a new browser profile (a cold visit: nothing cached), served from localhost
# under a sub-path, with web/time.js served as its test.js: the showcase opened and left to
# settle, then the split view, timed until its traced image is shown; then the raster view with
# the hybrid's four terms traced, timed until they are drawn at every pixel. It prints, per run,
# from the page's console: the first frame's time from the start of the page's load; the split
# view's time, from its step to the frame after the one that drew the finished traced image (the
# screenshot step's; both steps' times are the browser's, from its log); the page's own line for
# the traced image where the build logs one; and the hybrid's time, from the step that switches
# its four terms on in the raster view to its screenshot's, and the page's own line for the
# workers' terms (a build whose `wait traced` does not wait for the hybrid fails there). Compare two builds by running it on each in turn
# (web/README.md, "What a visit downloads, and how soon it draws"); a build older than time.js is
# timed the same way.
set -euo pipefail
cd "$(dirname "$0")/.."
dist=${1:-web/dist}
runs=${2:-3}
api=${3:-webgpu}
address=index.html?test
[ "${4:-}" = no-workers ] && address="index.html?test&workers=0"
port=${MIRADOR_WEB_PORT:-8766}
if [ ! -f "$dist/index.html" ]; then
    echo "$dist/ is not a built page: run bash web/build.sh first" >&2
    exit 1
fi
command -v chromium >/dev/null && command -v xvfb-run >/dev/null || {
    echo "needs chromium and xvfb (bash web/test.sh installs them)" >&2
    exit 1
}
. web/browser.sh
for run in $(seq "$runs"); do
    work=$(mktemp -d)
    serve_page "$dist" "$work" "$port"
    cp web/time.js "$work/site/course/mirador/test.js"
    open_page "$work" "$port" "$api" "$address"
    kill "$server" 2>/dev/null || true
    wait "$server" 2>/dev/null || true
    first=$(grep -ao "first frame [0-9]* ms" "$work/browser.log" | head -1 || true)
    shown=$(python3 web/steps.py "$work/browser.log" 'View(Split)' 'Screenshot("split.png")' || true)
    traced=$(grep -ao "traced [0-9]*×[0-9]* in [0-9.]* s[^\"]*" "$work/browser.log" | head -1 || true)
    hybrid=$(python3 web/steps.py "$work/browser.log" 'Set("hybrid={' 'Screenshot("hybrid.png")' || true)
    terms=$(grep -ao "the hybrid's terms of [0-9]* views traced by the workers in [0-9.]* s" "$work/browser.log" | tail -1 || true)
    shown=${shown:+split view shown traced in $shown s}
    hybrid=${hybrid:+the hybrid, four terms traced, drawn at every pixel in $hybrid s}
    echo "run $run: ${first:-no first frame logged}; ${shown:-the split view was not timed}${traced:+; $traced}; ${hybrid:-the hybrid was not timed}${terms:+ ($terms)}"
    sleep 1
    rm -rf "$work" 2>/dev/null || true
done
