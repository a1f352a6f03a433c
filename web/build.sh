#!/usr/bin/env bash
# Builds Mirador's page: `bash web/build.sh [OUT]` writes a static folder (default web/dist/) that
# any web server can serve: index.html, files.js, tracer.js, test.js, two modules (mirador.js and
# mirador_bg.wasm for WebGPU; mirador_webgl2.js and mirador_webgl2_bg.wasm for WebGL2, each
# the viewer with the built-in scenes inside) and the few assets fetched beside them. Installs what it needs when missing: rustup's
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

target_dir=$(cargo metadata --format-version 1 --no-deps | sed 's/.*"target_directory":"\([^"]*\)".*/\1/')

# Built beside the output and moved in at the end: a failed build leaves no half-written page.
staging=$(mktemp -d "${out%/}.partial.XXXXXX")
trap 'rm -rf "$staging"' EXIT
# Two modules: WebGPU's (the default features), and one with wgpu's WebGL2 backend instead (the
# `webgl2` feature alone), which the page loads where the browser has no WebGPU. Each without the function names (1 MB; a panic's
# stack then shows numbers) and the producers section.
for module in mirador mirador_webgl2; do
    features=$([ "$module" = mirador_webgl2 ] && echo "--no-default-features --features=webgl2" || true)
    cargo rustc --lib --profile web --locked --target wasm32-unknown-unknown --crate-type cdylib $features
    wasm-bindgen --target web --no-typescript --out-name "$module" --out-dir "$staging" \
        --remove-name-section --remove-producers-section \
        "$target_dir/wasm32-unknown-unknown/web/mirador.wasm"
done
cp web/index.html web/test.js web/tracer.js web/files.js "$staging/"
# The files the page fetches rather than carries, at the same paths: src/files.rs's FETCHED list.
fetched=$(sed -n 's/^pub const FETCHED: &\[&str\] = &\[\(.*\)\];$/\1/p' src/files.rs | tr -d '" ' | tr ',' ' ')
[ -n "$fetched" ] || { echo "web/build.sh: no FETCHED list in src/files.rs" >&2; exit 1; }
for path in $fetched; do
    mkdir -p "$staging/$(dirname "$path")"
    cp "$path" "$staging/$path"
done
rm -rf "$out"
mv "$staging" "$out"
trap - EXIT
echo "built $out/ ($(du -sh "$out" | cut -f1)); serve it with: bash web/serve.sh"
