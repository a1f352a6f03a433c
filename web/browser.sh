# Sourced by web/test.sh and web/time.sh: the page served under a sub-path, as a course site
# would host it (web/README.md, "Publishing the page"), opened in Chromium with WebGPU on
# SwiftShader (Vulkan on the CPU), headed under Xvfb (headless Chromium cannot make a WebGPU
# canvas's swap chain), with a new profile each time: a cold visit.

# serve_page DIST WORK PORT: copies DIST to WORK/site/course/mirador/ and serves WORK/site on
# PORT, storing what the page posts under WORK/capture/. Sets `server`.
serve_page() {
    mkdir -p "$2/site/course" "$2/capture"
    cp -r "$1" "$2/site/course/mirador"
    python3 web/serve.py --root "$2/site" --port "$3" --capture "$2/capture" >/dev/null &
    server=$!
    sleep 1
}

# open_page WORK PORT [webgl2]: opens the served page's `index.html?test` (web/test.js drives it),
# its console in WORK/browser.log, and waits up to 600 s for it to post `done` or `failed`. By
# default Chromium has WebGPU on SwiftShader; with `webgl2` it has no WebGPU (as on most Linux
# machines: `navigator.gpu` is there and gives no adapter) and WebGL2 on SwiftShader, so the page
# falls back to WebGL2 on its own. Sets `browser`, and closes it before returning.
open_page() {
    local gpu=(--enable-unsafe-webgpu --enable-features=Vulkan --use-angle=vulkan --use-vulkan=swiftshader
        --disable-vulkan-surface)
    [ "${3:-}" = webgl2 ] && gpu=(--use-angle=swiftshader)
    xvfb-run -a -s "-screen 0 1280x900x24" chromium --no-sandbox --no-first-run --window-size=1280,800 \
        --user-data-dir="$1/profile" "${gpu[@]}" --enable-logging=stderr --v=0 \
        "http://127.0.0.1:$2/course/mirador/index.html?test" 2>"$1/browser.log" &
    browser=$!
    for _ in $(seq 600); do
        [ -e "$1/capture/done" ] || [ -e "$1/capture/failed" ] && break
        sleep 1
    done
    pkill -P "$browser" 2>/dev/null || true
    kill "$browser" 2>/dev/null || true
}
