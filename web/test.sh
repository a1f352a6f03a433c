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
port=${MIRADOR_WEB_PORT:-8765}
. web/browser.sh
serve_page web/dist "$work" "$port"
browser=
trap 'kill $server $browser 2>/dev/null || true; rm -rf "$work/profile" "$work/site"' EXIT
# The page posts `done` after its last screenshot, or `failed` with the reason.
open_page "$work" "$port"
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
