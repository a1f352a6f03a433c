#!/usr/bin/env bash
# The course site's test: `bash web/site-test.sh [DIST]` builds the site (web/site.sh) unless
# given one, serves it under a sub-path (/course/) and checks, in order:
#   1. every link and image of every page names a file and an anchor the site has, every chapter
#      links into the page, the answers are left out (web/site_check.py);
#   2. every page of the book, in headless Chromium: it logs nothing to the console, and each of
#      its formulas is typeset (KaTeX's markup in place of the TeX);
#   3. every link into the page, opened in Chromium (headed under Xvfb) with WebGPU, then without
#      WebGPU (the page on WebGL2): the page posts its view once the link's scene, settings and
#      view are drawn, and tests/web_page.rs holds it against the native command it stands for.
# MIRADOR_SITE_LINKS=N opens every N-th link only (default 1: all of them, about 10 s each on two
# cores); MIRADOR_SITE_FROM=N starts at the N-th; MIRADOR_SITE_APIS="webgl2" runs one of the two
# APIs only (default "webgpu webgl2").
# Installs Chromium and Xvfb when missing, as web/test.sh does.
set -euo pipefail
cd "$(dirname "$0")/.."

. web/browser.sh
install_browser
site=${1:-}
if [ -z "$site" ]; then
    site=web/site-dist
    bash web/site.sh "$site"
fi

work=$(mktemp -d)
port=${MIRADOR_WEB_PORT:-8766}
serve_site "$site" "$work" "$port"
browser=
trap 'kill $server $browser 2>/dev/null || true; rm -rf "$work/profile" "$work/site"' EXIT

echo "1. the site's links"
python3 web/site_check.py "$work/site/course" --links "$work/links.tsv"

echo "2. every page of the book in the browser"
failures=0
while read -r page; do
    name=${page#"$work/site/course/"}
    dom=$(chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=10000 --enable-logging=stderr --v=0 \
        --user-data-dir="$work/headless" --dump-dom "http://127.0.0.1:$port/course/$name" 2>"$work/page.log" || true)
    if grep -aq "CONSOLE" "$work/page.log"; then
        echo "$name: the console says:" >&2
        grep -a "CONSOLE" "$work/page.log" >&2
        failures=$((failures + 1))
    fi
    formulas=$({ grep -o 'class="math-display"' <<<"$dom" || true; } | wc -l)
    typeset=$({ grep -o 'class="katex-display"' <<<"$dom" || true; } | wc -l)
    if [ "$formulas" != "$typeset" ]; then
        echo "$name: $typeset of its $formulas formulas typeset" >&2
        failures=$((failures + 1))
    fi
done < <(find "$work/site/course" -name '*.html' -not -path '*/mirador/*' -not -path '*/source/*' | sort)
[ "$failures" = 0 ] || { echo "$failures pages failed" >&2; exit 1; }
echo "   $(find "$work/site/course" -name '*.html' -not -path '*/mirador/*' -not -path '*/source/*' | wc -l) pages load with no console message, every formula typeset"

echo "3. every link into the page, drawn"
every=${MIRADOR_SITE_LINKS:-1}
from=${MIRADOR_SITE_FROM:-1}
failed=()
for api in ${MIRADOR_SITE_APIS:-webgpu webgl2}; do
    capture="$work/$api"
    rm -rf "$capture" "$work/profile"
    mkdir -p "$capture"
    n=0
    while IFS=$'\t' read -r page query; do
        n=$((n + 1))
        [ "$n" -ge "$from" ] && [ $(((n - 1) % every)) = 0 ] || continue
        rm -rf "$work/capture"
        mkdir -p "$work/capture"
        open_page "$work" "$port" "$([ "$api" = webgl2 ] && echo webgl2 || true)" \
            "index.html?$query&test=link&capture=link-$n"
        printf '%s\n%s\n' "$query" "$page" >"$capture/link-$n.query"
        if [ -e "$work/capture/done" ]; then
            cp "$work/capture/link-$n.png" "$work/capture/link-$n.png.view" "$capture/"
        else
            { [ -e "$work/capture/failed" ] && { cat "$work/capture/failed"; echo; } || echo "no frame in 600 s"; } >"$capture/link-$n.failed"
            grep -a "CONSOLE" "$work/browser.log" | tail -5 >>"$capture/link-$n.failed" || true
        fi
        echo "   $api, link $n ($page): $([ -e "$capture/link-$n.failed" ] && echo failed || echo drawn)"
    done <"$work/links.tsv"
    MIRADOR_WEB_CAPTURE="$capture" cargo test --locked --test web_page -- --ignored --nocapture the_course_links \
        || failed+=("$api")
done
[ ${#failed[@]} = 0 ] || { echo "the links drawn with ${failed[*]} differ from their commands (above)" >&2; exit 1; }
