#!/usr/bin/env bash
# The browser test: builds the page (web/build.sh), serves it, loads `index.html?test` in Chromium
# twice: with WebGPU on SwiftShader (Vulkan on the CPU), then without WebGPU, where the page draws
# with WebGL2 (on SwiftShader too); headed under Xvfb (headless Chromium cannot make a WebGPU
# canvas's swap chain, and the device is lost). Each time the page takes its screenshots through
# its own interface (web/test.js), and they are checked against the native renderers
# (`cargo test --test web_page the_page_draws -- --ignored`, tests/web_page.rs; the course-links
# test beside it is web/site-test.sh's). Installs Chromium and Xvfb when missing.
# Takes about 10 minutes cold (web/README.md); CI runs the web build's compile check instead
# (tests/web.rs).
set -euo pipefail
cd "$(dirname "$0")/.."

. web/browser.sh
install_browser
bash web/build.sh

work=$(mktemp -d)
port=${MIRADOR_WEB_PORT:-8765}
serve_page web/dist "$work" "$port"
browser=
trap 'kill $server $browser 2>/dev/null || true; rm -rf "$work/profile" "$work/site"' EXIT
# Twice: with WebGPU, then in a browser without it (WebGL2, chosen by the page on its own). Each
# run's screenshots are checked against the native renderers by the same test.
for api in webgpu webgl2; do
    rm -rf "$work/profile" "$work/capture"
    mkdir -p "$work/capture"
    # The page posts `done` after its last screenshot, or `failed` with the reason.
    open_page "$work" "$port" "$api"
    capture="$work/$api"
    rm -rf "$capture"
    mv "$work/capture" "$capture"
    if [ ! -e "$capture/done" ]; then
        echo "the page did not finish its test with $api; its console:" >&2
        grep -a "CONSOLE" "$work/browser.log" | tail -40 >&2
        [ -e "$capture/failed" ] && echo "the page said: $(cat "$capture/failed")" >&2
        exit 1
    fi
    # The device the page drew with, and what it logged of its times: the first frame (a cold
    # load: a new browser profile, nothing cached) and the traced image.
    want=$([ "$api" = webgl2 ] && echo "(Gl), WebGl2 profile" || echo "(BrowserWebGpu), Standard profile")
    if ! grep -aq "adapter: .*$want" "$work/browser.log"; then
        echo "the $api run did not draw with $want:" >&2
        grep -ao "adapter: [^\"]*" "$work/browser.log" >&2 || true
        exit 1
    fi
    echo "$api: $(grep -ao "adapter: [^\"]*profile" "$work/browser.log" | tail -1)"
    grep -ao "first frame [0-9]* ms after the page started loading\|traced [0-9]*×[0-9]* in [0-9.]* s ([^)\"]*)" "$work/browser.log" || true
    MIRADOR_WEB_CAPTURE="$capture" cargo test --locked --test web_page the_page_draws -- --ignored --nocapture
    echo "the page's screenshots ($api): $capture"
done
