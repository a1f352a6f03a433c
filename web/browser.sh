# Sourced by web/test.sh, web/time.sh, web/site-test.sh and web/site-time.sh: the page served under
# a sub-path, as a course site would host it (web/README.md, "Publishing the page"), opened in
# Chromium with WebGPU on SwiftShader (Vulkan on the CPU), headed under Xvfb (headless Chromium
# cannot make a WebGPU canvas's swap chain), with a new profile each time: a cold visit.

# install_browser: Chromium, Xvfb and Python 3, where missing.
install_browser() {
    local missing=()
    command -v chromium >/dev/null || missing+=(chromium)
    command -v xvfb-run >/dev/null || missing+=(xvfb)
    command -v python3 >/dev/null || missing+=(python3)
    if [ ${#missing[@]} -gt 0 ]; then
        apt-get update && apt-get install -y "${missing[@]}"
    fi
}

# serve_page DIST WORK PORT: copies DIST to WORK/site/course/mirador/ and serves WORK/site on
# PORT, storing what the page posts under WORK/capture/. Sets `server`.
serve_page() {
    mkdir -p "$2/site/course" "$2/capture"
    cp -r "$1" "$2/site/course/mirador"
    python3 web/serve.py --root "$2/site" --port "$3" --capture "$2/capture" >/dev/null &
    server=$!
    sleep 1
}

# serve_site DIST WORK PORT: the course's site (web/site.sh) served as WORK/site/course/, the
# page at course/mirador/, as serve_page. Sets `server`.
serve_site() {
    mkdir -p "$2/site" "$2/capture"
    rm -rf "$2/site/course"
    cp -r "$1" "$2/site/course"
    python3 web/serve.py --root "$2/site" --port "$3" --capture "$2/capture" >/dev/null &
    server=$!
    sleep 1
}

# open_page WORK PORT [webgl2] [ADDRESS]: opens the served page's `index.html?test` (web/test.js
# drives it; or ADDRESS, from the page's folder: `index.html?scene=…&test=link&capture=NAME`),
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
        "http://127.0.0.1:$2/course/mirador/${4:-index.html?test}" 2>"$1/browser.log" &
    browser=$!
    for _ in $(seq 600); do
        [ -e "$1/capture/done" ] || [ -e "$1/capture/failed" ] && break
        sleep 1
    done
    pkill -P "$browser" 2>/dev/null || true
    kill "$browser" 2>/dev/null || true
}
