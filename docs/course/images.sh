#!/usr/bin/env bash
# Makes every image of the course (docs/course/images/) again, from the release build of Mirador:
# the teaching examples write their sheets, and the `mirador` command writes the rest (mostly
# `compare` sheets: raster | ray traced | FLIP error). Each chapter's captions repeat the command
# that made its images.
#
#     bash docs/course/images.sh
#
# Runs from any folder; needs what Mirador needs (Vulkan or GL, e.g. Mesa's lavapipe). Takes a few
# minutes on two cores, most of it the examples. Look at every image that changed before
# committing it.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=docs/course/images
mkdir -p "$out"

# One build for the binary and the examples (built apart, they would build the library twice,
# once with the examples' dev-dependencies and once without), then run from wherever cargo put it.
cargo build --release --locked --bin mirador --examples
target=$(cargo metadata --format-version 1 --no-deps | sed -e 's/.*"target_directory":"\([^"]*\)".*/\1/')
mirador() { "$target/release/mirador" "$@"; }
example() { "$target/release/examples/$1" "$out/$2"; }
course=assets/scenes/course
small=(--width 320 --height 180)
mid=(--width 400 --height 225)
rm -f "$out"/*.png

# 1. The camera and primary rays
mirador compare assets/scenes/seed-simple.toml -o "$out/camera-seed-simple.png"
mirador compare "$course/camera-orthographic.toml" "${mid[@]}" -o "$out/camera-orthographic.png"

# 2. The illumination model
mirador compare "$course/illumination-terms.toml" "${mid[@]}" -o "$out/illumination-compare.png"
mirador render "$course/illumination-terms.toml" "${small[@]}" -o "$out/illumination-ambient.png" \
    --set terms.diffuse=false --set terms.specular=false
mirador render "$course/illumination-terms.toml" "${small[@]}" -o "$out/illumination-diffuse.png" \
    --set terms.ambient=false --set terms.specular=false
mirador render "$course/illumination-terms.toml" "${small[@]}" -o "$out/illumination-specular.png" \
    --set terms.ambient=false --set terms.diffuse=false

# 3. Mipmaps and trilinear filtering
example mipmaps mipmaps.png
mirador compare "$course/mipmaps-floor.toml" "${mid[@]}" -o "$out/mipmaps-level-colours.png" \
    --set 'textures.filter="level_colour"'

# 4. Bump mapping
example bump_mapping bump_mapping.png
mirador compare assets/scenes/bumps.toml "${mid[@]}" -o "$out/bump-compare.png"

# 4b. Displacement and parallax mapping: the ball and the plane with each method, side by side
# (bump | parallax | displacement, all rasterized), composed with Pillow.
relief=$(mktemp -d)
for scene in sphere plane; do
    for method in normal parallax displacement; do
        mirador render "$course/displacement-$scene.toml" --width 240 --height 135 \
            -o "$relief/$scene-$method.png" --set "bump.method=\"$method\""
    done
done
if python3 -c 'import PIL' 2>/dev/null; then
    python3 - "$relief" "$out/displacement.png" <<'PY'
import sys
from PIL import Image
folder, out = sys.argv[1:]
rows = [[Image.open(f"{folder}/{scene}-{method}.png").convert("RGB") for method in ("normal", "parallax", "displacement")] for scene in ("sphere", "plane")]
w, h = rows[0][0].size
sheet = Image.new("RGB", (3 * w, 2 * h))
for j, row in enumerate(rows):
    for i, image in enumerate(row):
        sheet.paste(image, (i * w, j * h))
sheet.save(out)
PY
else
    echo "Pillow not found: displacement.png is not made"
fi
rm -rf "$relief"

# 5. Cast shadows
example shadows shadows.png
mirador compare "$course/shadows-methods.toml" "${mid[@]}" -o "$out/shadows-compare.png"

# 6. Transparency in Z order
example transparency transparency.png
mirador compare "$course/transparency-refraction.toml" "${mid[@]}" -o "$out/transparency-refraction.png"
mirador compare "$course/transparency-refraction.toml" "${mid[@]}" -o "$out/transparency-refraction-screen.png" \
    --set 'transparency.refraction="screen"' --set terms.fresnel=true

# 7. Planar mirrors
example planar_mirror planar_mirror.png
mirador compare "$course/mirror-pair.toml" "${mid[@]}" -o "$out/mirrors-compare.png"

# 8. Environment maps
example environment_maps environment_maps.png
mirador compare "$course/environment-ball.toml" "${mid[@]}" -o "$out/environment-compare.png"
mirador compare "$course/environment-ball.toml" "${mid[@]}" -o "$out/environment-ground.png" \
    --set 'environment.parallax="ground"'

# 9. Whitted ray tracing
mirador trace "$course/whitted-depth.toml" "${small[@]}" --max-depth 0 -o "$out/whitted-depth-0.png"
mirador trace "$course/whitted-depth.toml" "${small[@]}" --max-depth 1 -o "$out/whitted-depth-1.png"
mirador trace "$course/whitted-depth.toml" "${small[@]}" --max-depth 2 -o "$out/whitted-depth-2.png"
mirador trace "$course/whitted-depth.toml" "${small[@]}" --max-depth 5 -o "$out/whitted-depth-5.png"
mirador compare assets/scenes/showcase.toml "${mid[@]}" -o "$out/showcase-compare.png"

# 10. Anti-aliasing and progressive refinement
mirador trace "$course/aliasing-edges.toml" --aa center -o "$out/aa-center.png"
mirador trace "$course/aliasing-edges.toml" --aa jittered --spp 4 -o "$out/aa-jittered.png"
mirador trace "$course/aliasing-edges.toml" --aa adaptive -o "$out/aa-adaptive.png"
mirador compare "$course/aliasing-edges.toml" "${mid[@]}" --aa adaptive -o "$out/aa-compare.png"

# 11. Volume ray casting
example volume volume.png
mirador compare "$course/volume-phantom.toml" "${mid[@]}" -o "$out/volume-compare.png"

# 12. Where the error comes from
mirador budget "$course/mirror-pair.toml" "${mid[@]}" --set mirrors.depth=1 --sheet "$out/budget-mirror-pair.png"

# Mirador writes PNGs quickly rather than small, with an alpha channel that is always opaque.
# Stored again as RGB at zlib's best compression, they take about half the space, pixel for
# pixel the same (Python's Pillow does it; without Pillow they are left as written).
if python3 -c 'import PIL' 2>/dev/null; then
    python3 - "$out"/*.png <<'PY'
import sys
from PIL import Image
for path in sys.argv[1:]:
    image = Image.open(path)
    image.load()
    if image.mode == "RGBA" and image.getchannel("A").getextrema() == (255, 255):
        image = image.convert("RGB")
    image.save(path, optimize=True)
PY
else
    echo "Pillow not found: the images are left as Mirador wrote them (about twice as large)"
fi
du -ch "$out"/*.png | tail -n 1
