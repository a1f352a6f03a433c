#!/usr/bin/env bash
# The course site's first-load times: `bash web/site-time.sh [DIST] [RUNS]` (default
# web/site-dist/, 3 runs) serves the site under /course/ and loads each chapter cold (a new
# headless Chromium profile each time) inside a page of the same origin, which times it from the
# request to the chapter's load event: its style sheets, scripts and fonts in, and every formula
# typeset (web/site/math.js runs before that event). Prints each chapter's times and the bytes it
# downloaded (uncompressed: the test server sends files as they are), then the median of all.
set -euo pipefail
cd "$(dirname "$0")/.."
site=${1:-web/site-dist}
runs=${2:-3}
[ -e "$site/index.html" ] || { echo "web/site-time.sh: $site is not a built site (bash web/site.sh)" >&2; exit 1; }

work=$(mktemp -d)
port=${MIRADOR_WEB_PORT:-8767}
. web/browser.sh
serve_site "$site" "$work" "$port"
trap 'kill $server 2>/dev/null || true; rm -rf "$work"' EXIT
# The timing page, in the served copy only.
cat >"$work/site/course/time.html" <<'EOF'
<!doctype html>
<meta charset="utf-8">
<body>
<script>
const page = new URLSearchParams(location.search).get("page");
const frame = document.createElement("iframe");
frame.style = "width: 1280px; height: 800px";
const start = performance.now();
frame.onload = () => {
  const ms = performance.now() - start;
  const timing = frame.contentWindow.performance;
  const bytes = [...timing.getEntriesByType("navigation"), ...timing.getEntriesByType("resource")]
    .reduce((sum, entry) => sum + entry.decodedBodySize, 0);
  fetch(`/capture/${page}`, { method: "POST", body: `${ms.toFixed(0)} ${bytes}` });
};
frame.src = page;
document.body.append(frame);
</script>
EOF
all=()
for page in "$site"/[0-9][0-9]-*.html; do
    name=$(basename "$page")
    times=()
    for run in $(seq "$runs"); do
        rm -f "$work/capture/$name"
        chromium --headless --no-sandbox --disable-gpu --user-data-dir="$work/profile-$name-$run" \
            "http://127.0.0.1:$port/course/time.html?page=$name" >/dev/null 2>&1 &
        browser=$!
        for _ in $(seq 300); do
            [ -s "$work/capture/$name" ] && break
            sleep 0.1
        done
        kill "$browser" 2>/dev/null || true
        wait "$browser" 2>/dev/null || true
        [ -s "$work/capture/$name" ] || { echo "$name did not load in 30 s" >&2; exit 1; }
        read -r ms bytes <"$work/capture/$name" || true  # (no newline at its end)
        times+=("$ms")
        all+=("$ms")
    done
    echo "$name: ${times[*]} ms, $((bytes / 1024)) KiB"
done
median=$(printf '%s\n' "${all[@]}" | sort -n | awk '{a[NR]=$1} END {print a[int((NR + 1) / 2)]}')
echo "median of ${#all[@]} loads: $median ms"
