#!/usr/bin/env bash
# Builds the course as one static site: `bash web/site.sh [DIST] [--answers] [--page DIR]` (default
# web/site-dist/). DIST/index.html is the course (docs/course, made a book by mdBook, its
# formulas typeset by KaTeX, searchable), DIST/mirador/ the page (web/build.sh) that every
# command of the chapters opens in, with its scene, settings and view. Every link is relative:
# serve DIST at any address or sub-path (web/README.md, "The course as a site").
#
# --page DIR takes a page web/build.sh has built (web/dist/) instead of building it again.
# --answers adds the answers (docs/course/answers.md), for a teacher's own copy; without it the
# site has none. MIRADOR_SITE_SOURCE=https://…/blob/COMMIT sends the links to the repository's
# files (sources, tests) to the forge; without it the site carries a copy of each (source/).
#
# Installs what it needs when missing: mdBook (at the version below, from crates.io, about 3
# minutes to build once) and KaTeX (from npm's registry, its checksum checked); then the page
# (web/build.sh: its own tools, about 8 minutes cold) and Mirador itself, whose `mirador book` is
# the book's preprocessor.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

out=web/site-dist
answers=false
page=
while [ $# -gt 0 ]; do
    case "$1" in
        --answers) answers=true ;;
        --page) page=${2:?--page needs the built page\'s folder}; shift ;;
        -*) echo "web/site.sh: unknown option $1 (usage: bash web/site.sh [DIST] [--answers] [--page DIR])" >&2; exit 2 ;;
        *) out=$1 ;;
    esac
    shift
done

MDBOOK_VERSION=0.5.4
KATEX_VERSION=0.16.22
KATEX_SHA256=e9e0d167db3175481cbadaff38e8d90b130f6a3ddb451a47e43c577fd511f365

if [ "$(mdbook --version 2>/dev/null)" != "mdbook v$MDBOOK_VERSION" ]; then
    cargo install mdbook --locked --version "$MDBOOK_VERSION" --no-default-features --features search
fi
cache=${XDG_CACHE_HOME:-$HOME/.cache}/mirador
katex=$cache/katex-$KATEX_VERSION.tgz
if ! echo "$KATEX_SHA256  $katex" | sha256sum --check --status 2>/dev/null; then
    mkdir -p "$cache"
    command -v curl >/dev/null || { apt-get update && apt-get install -y curl; }
    curl -fsSL -o "$katex.partial" "https://registry.npmjs.org/katex/-/katex-$KATEX_VERSION.tgz"
    echo "$KATEX_SHA256  $katex.partial" | sha256sum --check --quiet
    mv "$katex.partial" "$katex"
fi

# Built beside the output and moved in at the end: a failed build leaves no half-written site.
staging=$(cd "$(mktemp -d "${out%/}.partial.XXXXXX")" && pwd)
trap 'rm -rf "$staging"' EXIT
cargo build --release --locked --bin mirador
if [ -n "$page" ]; then
    [ -e "$page/index.html" ] && [ -e "$page/mirador_bg.wasm" ] || { echo "web/site.sh: $page is not a built page (web/build.sh)" >&2; exit 1; }
    cp -r "$page" "$staging/page"
else
    bash web/build.sh "$staging/page"
fi

# The book's sources: the course, and the documents of docs/ it links, under reference/.
book=$staging/book
mkdir -p "$book/src/reference" "$book/site/katex"
cp -r docs/course/. "$book/src/"
rm -f "$book/src/images.sh"
$answers || rm "$book/src/answers.md"
cp docs/scene-format.md docs/architecture.md docs/performance.md "$book/src/reference/"
cp web/site/math.js web/site/mirador.css "$book/site/"
tar xzf "$katex" -C "$staging" package/dist
cp "$staging/package/dist/katex.min.js" "$staging/package/dist/katex.min.css" "$book/site/katex/"

# The table of contents: each page by its first heading.
title() { sed -n 's/^# //p' "$1" | head -1; }
{
    echo "# Summary"
    echo
    echo "[$(title docs/course/README.md)](README.md)"
    echo
    for chapter in docs/course/[0-9][0-9]-*.md docs/course/labs.md; do
        echo "- [$(title "$chapter")]($(basename "$chapter"))"
    done
    $answers && echo "- [$(title docs/course/answers.md)](answers.md)"
    echo
    echo "# Reference"
    echo
    for doc in scene-format architecture performance; do
        echo "- [$(title "docs/$doc.md")](reference/$doc.md)"
    done
} >"$book/src/SUMMARY.md"

cat >"$book/book.toml" <<EOF
[book]
title = "Mirador: the classic realistic-rendering techniques"
language = "en"
src = "src"

[preprocessor.mirador]
command = "$repo/target/release/mirador book"
repository = "$repo"
source = "${MIRADOR_SITE_SOURCE:-}"

[output.html]
additional-css = ["site/katex/katex.min.css", "site/mirador.css"]
additional-js = ["site/katex/katex.min.js", "site/math.js"]
no-section-label = true

[output.html.search]
enable = true
EOF
mdbook build "$book" --dest-dir "$staging/site"
# KaTeX's fonts, beside its style sheet, which names them (mdBook copies only the files named in
# book.toml). WOFF2 only: every browser that runs the page reads it, and picks it first.
mkdir -p "$staging/site/site/katex/fonts"
cp "$staging/package/dist/fonts/"*.woff2 "$staging/site/site/katex/fonts/"
mv "$staging/page" "$staging/site/mirador"
rm -rf "$out"
mv "$staging/site" "$out"
trap - EXIT
rm -rf "$staging"
echo "built $out/ ($(du -sh "$out" | cut -f1)): the course at index.html, the page at mirador/"
