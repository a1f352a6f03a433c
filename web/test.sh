#!/usr/bin/env bash
# The browser test: builds the page (web/build.sh), serves it, loads `index.html?test` in Chromium
# with WebGPU on SwiftShader (Vulkan on the CPU), headed under Xvfb (headless Chromium cannot make
# a WebGPU canvas's swap chain, and the device is lost), lets the page take its screenshots
# through its own interface (web/test.js), then checks them against the native renderers
# (`cargo test --test web_page -- --ignored`, tests/web_page.rs). Installs Chromium and Xvfb when
# missing.
# Takes about 10 minutes cold (web/README.md); CI runs the web build's compile check instead
# (tests/web.rs).
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v chromium >/dev/null || missing+=(chromium)
command -v xvfb-run >/dev/null || missing+=(xvfb)
command -v python3 >/dev/null || missing+=(python3)
if [ ${#missing[@]} -gt 0 ]; then
    apt-get update && apt-get install -y "${missing[@]}"
fi
bash web/build.sh

work=$(mktemp -d)
capture="$work/capture"
mkdir -p "$capture"
port=${MIRADOR_WEB_PORT:-8765}
# Served under a sub-path, as a course site would host it (web/README.md, "Publishing the page").
site="$work/site"
mkdir -p "$site/course"
cp -r web/dist "$site/course/mirador"
python3 web/serve.py --root "$site" --port "$port" --capture "$capture" &
server=$!
trap 'kill $server $browser 2>/dev/null || true; rm -rf "$work/profile" "$site"' EXIT
sleep 1
browser=
xvfb-run -a -s "-screen 0 1280x900x24" chromium --no-sandbox --no-first-run --window-size=1280,800 \
    --user-data-dir="$work/profile" --enable-unsafe-webgpu --enable-features=Vulkan --use-angle=vulkan \
    --use-vulkan=swiftshader --disable-vulkan-surface --enable-logging=stderr --v=0 \
    "http://127.0.0.1:$port/course/mirador/index.html?test" 2>"$work/browser.log" &
browser=$!

# The page posts `done` after its last screenshot, or `failed` with the reason.
for _ in $(seq 600); do
    [ -e "$capture/done" ] || [ -e "$capture/failed" ] && break
    sleep 1
done
pkill -P $browser 2>/dev/null || true
kill $browser 2>/dev/null || true
if [ ! -e "$capture/done" ]; then
    echo "the page did not finish its test; its console:" >&2
    grep -a "CONSOLE" "$work/browser.log" | tail -40 >&2
    [ -e "$capture/failed" ] && echo "the page said: $(cat "$capture/failed")" >&2
    exit 1
fi
# What the page logged of its times: the first frame (a cold load: a new browser profile, nothing
# cached) and the traced image.
grep -ao "first frame [0-9]* ms after the page started loading\|traced [0-9]*×[0-9]* in [0-9.]* s ([a-z ]*)" "$work/browser.log" || true
MIRADOR_WEB_CAPTURE="$capture" cargo test --locked --test web_page -- --ignored --nocapture
echo "the page's screenshots: $capture"
