// web/time.sh's steps, served in test.js's place (so a build from before this file is timed the
// same way): the showcase as it opens, drawn and left to settle; then the split view, the wait
// for its traced image and a screenshot. The page logs each step as it runs; time.sh times the
// split view from its step to the screenshot's, which runs at the frame after the one that drew
// the finished traced image.
const SETTLE_MS = 3000;

export function run(mirador) {
  window.miradorScreenshot = async (name) => {
    if (name === "settled.png") {
      setTimeout(() => {
        for (const step of ["view split", "wait traced", "screenshot split.png"]) mirador.step(step);
      }, SETTLE_MS);
    } else {
      await fetch("/capture/done", { method: "POST", body: "done" });
    }
  };
  window.miradorError = (text) => fetch("/capture/failed", { method: "POST", body: text });
  for (const step of ["overlay off", "wait 2s", "screenshot settled.png"]) mirador.step(step);
}
