// web/time.sh's steps, served in test.js's place (so a build from before this file is timed the
// same way): the showcase as it opens, drawn and left to settle; then the split view, the wait
// for its traced image and a screenshot; then the raster view with one of the hybrid's terms,
// left to settle, its four terms switched on in one step, the wait for its terms at every pixel
// and a screenshot. The page logs each step as it runs; time.sh times each view from its step to its
// screenshot's, which runs at the frame after the one that drew the finished image.
const SETTLE_MS = 3000;
const HYBRID = "set hybrid={shadows=true, reflections=true, transmission=true, textures=true}";

export function run(mirador) {
  window.miradorScreenshot = async (name) => {
    if (name === "settled.png") {
      setTimeout(() => {
        for (const step of ["view split", "wait traced", "screenshot split.png"]) mirador.step(step);
      }, SETTLE_MS);
    } else if (name === "split.png") {
      // One term first: the shading variants the hybrid draws with are compiled then (the four
      // terms share them), not in the timed steps.
      mirador.step("view raster");
      mirador.step("set hybrid.textures=true");
      setTimeout(() => {
        for (const step of [HYBRID, "wait traced", "screenshot hybrid.png"]) mirador.step(step);
      }, SETTLE_MS);
    } else {
      await fetch("/capture/done", { method: "POST", body: "done" });
    }
  };
  window.miradorError = (text) => fetch("/capture/failed", { method: "POST", body: text });
  for (const step of ["overlay off", "wait 2s", "screenshot settled.png"]) mirador.step(step);
}
