// The browser test's page side (web/test.sh loads `index.html?test`). Everything goes through the
// page's own interface, `mirador.step(...)`, which the scene menu and the file picker use too:
// the showcase as it opens, the shadows toggled off, the split view once the tracer has finished
// in the page, the difference view, and the hybrid's traced shadows over acned shadow maps. Each screenshot (the whole canvas, PNG) is posted to the
// test server with the 3D view's rectangle; `done` ends the run, `failed` says why it stopped.
const post = (path, body, view) =>
  fetch(path, { method: "POST", body, headers: view ? { "X-View": view.join(" ") } : {} });

export function run(mirador) {
  let expected = 0;
  let posted = 0;
  window.miradorScreenshot = async (name, png, view) => {
    await post(`/capture/${name}`, png, view);
    if (++posted === expected) await post("/capture/done", "done");
  };
  window.miradorError = (text) => post("/capture/failed", text);
  const steps = [
    "overlay off",
    "wait 2s",
    "screenshot raster.png",
    "set shadows.enabled=false",
    "wait 2s",
    "screenshot no-shadows.png",
    "set shadows.enabled=true",
    "view split",
    "wait traced",
    "wait 1s",
    "screenshot split.png",
    "view difference",
    "wait traced",
    "wait 1s",
    "screenshot difference.png",
    // The hybrid in the page: shadow maps without bias (acne everywhere), their visibility
    // traced instead, refined on the page's thread.
    "view raster",
    "set shadows.depth_bias=0",
    "set shadows.slope_bias=0",
    "set shadows.normal_offset=0",
    "set hybrid.shadows=true",
    "wait 10s",
    "screenshot hybrid.png",
  ];
  expected = steps.filter((s) => s.startsWith("screenshot")).length;
  for (const step of steps) mirador.step(step);
}
