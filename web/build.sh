#!/usr/bin/env bash
# Builds Mirador's page: `bash web/build.sh [OUT]` writes a static folder (default web/dist/) that
# any web server can serve: index.html, mirador.js and mirador_bg.wasm (the viewer, with the
# built-in scenes and assets inside), test.js. Installs what it needs when missing: rustup's
# wasm32-unknown-unknown standard library, and wasm-bindgen-cli at the version Cargo.lock pins
# (it must equal the wasm-bindgen crate's). Cold: about 6 minutes for wasm-bindgen-cli, then the
# build (web/README.md has the figures).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-web/dist}

if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    rustup target add wasm32-unknown-unknown
fi
version=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"$/\1/p}' Cargo.lock)
if [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $version" ]; then
    # Not --locked: wasm-bindgen-cli's own lock names a crate version the index no longer has.
    cargo install wasm-bindgen-cli --version "$version"
fi

cargo rustc --lib --profile web --locked --target wasm32-unknown-unknown --crate-type cdylib
target_dir=$(cargo metadata --format-version 1 --no-deps | sed 's/.*"target_directory":"\([^"]*\)".*/\1/')

# Built beside the output and moved in at the end: a failed build leaves no half-written page.
staging=$(mktemp -d "${out%/}.partial.XXXXXX")
trap 'rm -rf "$staging"' EXIT
# Without the function names (1 MB; a panic's stack then shows numbers) and the producers section.
wasm-bindgen --target web --no-typescript --out-name mirador --out-dir "$staging" \
    --remove-name-section --remove-producers-section \
    "$target_dir/wasm32-unknown-unknown/web/mirador.wasm"
cp web/index.html web/test.js web/tracer.js "$staging/"
rm -rf "$out"
mv "$staging" "$out"
trap - EXIT
echo "built $out/ ($(du -sh "$out" | cut -f1)); serve it with: bash web/serve.sh"
