"""Embree 4 on the trace benchmark's work, for the ratio docs/performance.md reports.

The same mesh (the displaced sphere, 1,046,528 triangles) and the same 512 x 512 primary rays as
`cargo bench --bench trace`, which writes them with `--dump=FOLDER`; Embree through the Python
package `embreex` (Embree 4 prebuilt, no C++ build), one ray at a time (`rtcIntersect1`) on one
thread, as its scene's `run` loops. Timed by this thread's CPU time, the best of REPEATS passes,
as the Rust benchmark times its one-thread passes. Both scene modes are run: Embree's default and
`robust` (RTC_SCENE_FLAG_ROBUST, watertight like Mirador's triangle test).

    python3 -m pip install embreex numpy
    cargo bench --bench trace -- none --dump=target/trace-work
    python3 benches/embree.py target/trace-work
"""

import sys
import time

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

REPEATS = 3


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit("usage: python3 benches/embree.py FOLDER (written by cargo bench --bench trace -- --dump=FOLDER)")
    folder = sys.argv[1]
    triangles = np.fromfile(f"{folder}/triangles.f32", dtype="<f4").reshape(-1, 3, 3)
    rays = np.fromfile(f"{folder}/primary.f32", dtype="<f4").reshape(-1, 6)
    origins = np.ascontiguousarray(rays[:, :3])
    directions = np.ascontiguousarray(rays[:, 3:])
    print(f"mesh: {len(triangles)} triangles; {len(rays)} primary rays; best of {REPEATS}; one thread")
    for robust in (False, True):
        scene = rtcore_scene.EmbreeScene(robust=robust)
        TriangleMesh(scene, triangles)
        start = time.perf_counter()
        hits = scene.run(origins, directions)  # builds the tree on first use
        build = time.perf_counter() - start
        best = float("inf")
        for _ in range(REPEATS):
            start = time.thread_time()
            hits = scene.run(origins, directions)
            best = min(best, time.thread_time() - start)
        mode = "robust" if robust else "default"
        print(
            f"embree 4 ({mode:<7}) first run with build {build:6.2f} s; "
            f"primary 1T {len(rays) / best / 1e6:6.2f} Mr/s; hits {int((hits >= 0).sum())}"
        )


if __name__ == "__main__":
    main()
