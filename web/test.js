// The browser test's page side (web/test.sh loads `index.html?test`). Everything goes through the
// page's own interface, `mirador.step(...)`, which the scene menu and the file picker use too:
// the showcase as it opens, the shadows toggled off, the split view once the tracer has finished
// in the page, the difference view, the hybrid's traced shadows over acned shadow maps, a lab's
// stub, reference and difference, a student's edits, a scene whose volume the page fetches, screen-space refraction, a displaced ball, and the lab's checks run in the page on a wrong solution
// and a right one (their results.json posted as `lab-wrong.json`, `lab-right.json`, with the
// texts checked). Each screenshot (the whole canvas, PNG) is posted to the
// test server with the 3D view's rectangle; `done` ends the run, `failed` says why it stopped.
const post = (path, body, view) =>
  fetch(path, { method: "POST", body, headers: view ? { "X-View": view.join(" ") } : {} });

// Every screenshot, check text and results.json the run posts, counted: `done` follows the last.
let expected = 0;
let posted = 0;
const count = async () => {
  if (++posted === expected) await post("/capture/done", "done");
};

export function run(mirador) {
  // What the page does next once a screenshot is posted: the lab's steps follow one another.
  const after = {
    "lab-difference.png": () => editTheLab(mirador),
    "lab-solved.png": () => typo(mirador),
    "lab-typo.png": () => check(mirador, "lab-wrong", WRONG),
    "lab-checked.png": () => check(mirador, "lab-right", REFLECTION),
  };
  window.miradorScreenshot = async (name, png, view) => {
    await post(`/capture/${name}`, png, view);
    after[name]?.();
    await count();
  };
  window.miradorError = (text) => post("/capture/failed", text);
  // The page's own handler (it enables the results' download) keeps running.
  const page = window.miradorLabChecked;
  window.miradorLabChecked = async (json) => {
    page?.(json);
    await post(`/capture/${checking}.json`, json);
    await count();
  };
  const steps = [
    "overlay off",
    "wait 2s",
    "screenshot raster.png",
    "set shadows.enabled=false",
    "wait 2s",
    "screenshot no-shadows.png",
    "set shadows.enabled=true",
    // The raster view drawn again with its shadows (a second of SwiftShader's work) before the
    // split view, so that the traced time web/test.sh prints is the tracer's, as web/time.sh
    // times it, not shared with that frame.
    "wait 2s",
    "view split",
    "wait traced",
    "wait 1s",
    "screenshot split.png",
    "view difference",
    "wait traced",
    "wait 1s",
    "screenshot difference.png",
    // The hybrid in the page: shadow maps without bias (acne everywhere), their visibility
    // traced instead: coarse on the page's thread, then at every pixel by the tracer's workers
    // (with WebGL2 too), or on the page's thread where there are none.
    "view raster",
    "set shadows.depth_bias=0",
    "set shadows.slope_bias=0",
    "set shadows.normal_offset=0",
    "set hybrid.shadows=true",
    "wait traced",
    "screenshot hybrid.png",
    // (the screenshot is posted with the view's rectangle a frame or two later: the lab's editor
    // must not have narrowed the view by then)
    "wait 2s",
    // A scene that names a file the page fetches beside its module (the phantom volume).
    "set hybrid.shadows=false",
    "load assets/scenes/course/volume-phantom.toml",
    "wait 4s",
    "screenshot phantom.png",
    "wait 2s",
    // Screen-space refraction, which follows rays through the view's depth (read with textureLoad).
    "load assets/scenes/refraction.toml",
    "set transparency.refraction=screen",
    "wait 4s",
    "screenshot refraction.png",
    "wait 2s",
    // Displacement: with WebGPU tessellated by the page's compute shader, with WebGL2 (no compute)
    // the uniform mesh the tracer draws.
    "load assets/scenes/course/displacement-sphere.toml",
    "set bump.method=displacement",
    "wait 4s",
    "screenshot displaced.png",
    "wait 2s",
    // The lab in the page: the planar-mirrors lab's stub (its neutral reflection: the mirror
    // shows the room unreflected), then the reference; the editor narrows the view.
    "lab open planar-mirrors",
    "wait 4s",
    "screenshot lab-stub.png",
    "lab reference",
    "wait 4s",
    "screenshot lab-reference.png",
    "lab difference",
    "wait 4s",
    "screenshot lab-difference.png",
  ];
  const screenshots = [...steps, ...LAB_EDITS, ...LAB_TYPO, ...CHECK].filter((s) => s.startsWith("screenshot"));
  // And each check's text and results.json.
  expected = screenshots.length + 4;
  for (const step of steps) mirador.step(step);
}

// What a student does next, once the reference and the difference are shown: writes the reflection (this text, as
// if typed into the editor), sees it drawn, then saves a version with a typo: the view keeps the
// last version that compiled and shows the problem.
const REFLECTION = `fn mirror_reflection(plane: vec4f) -> mat4x4f {
    let n = plane.xyz;
    let d = plane.w;
    return mat4x4f(
        vec4f(1.0 - 2.0 * n.x * n.x, -2.0 * n.x * n.y, -2.0 * n.x * n.z, 0.0),
        vec4f(-2.0 * n.y * n.x, 1.0 - 2.0 * n.y * n.y, -2.0 * n.y * n.z, 0.0),
        vec4f(-2.0 * n.z * n.x, -2.0 * n.z * n.y, 1.0 - 2.0 * n.z * n.z, 0.0),
        vec4f(-2.0 * d * n.x, -2.0 * d * n.y, -2.0 * d * n.z, 1.0),
    );
}
`;
const LAB_EDITS = ["lab student", "wait 4s", "screenshot lab-solved.png", "wait 1s"];
const LAB_TYPO = ["wait 4s", "screenshot lab-typo.png"];

function editTheLab(mirador) {
  mirador.set_lab_text(REFLECTION);
  for (const step of LAB_EDITS) mirador.step(step);
}

// The typo once the solved screenshot is posted.
function typo(mirador) {
  mirador.set_lab_text(REFLECTION.replace("let d = plane.w;", "let d = plane.w"));
  for (const step of LAB_TYPO) mirador.step(step);
}

// The lab's checks in the page, as a student runs them with the panel's Check button: first on a
// wrong solution (the mirror's offset not doubled: the lab's known mistake "d not doubled"),
// whose panel is screenshot, then on the right one. Each check's text and results.json go to the
// test server, which holds them against the native checker's (tests/web_page.rs).
const WRONG = REFLECTION.replaceAll("-2.0 * d * n.", "-d * n.");
const CHECK = ["lab check", "wait checked", "wait 1s", "screenshot lab-checked.png"];
let checking = "";

async function check(mirador, name, text) {
  checking = name;
  await post(`/capture/${name}.wgsl`, text);
  mirador.set_lab_text(text);
  for (const step of name === "lab-wrong" ? CHECK : CHECK.slice(0, 2)) mirador.step(step);
  await count();
}

// web/site-test.sh's check of one of the course's links (`…&test=link&capture=NAME`): the
// page has queued the address's steps (web/index.html); once they have run and the view is drawn
// (the traced image too, where the view shows it), its screenshot is posted as NAME.png, then
// `done`. tests/web_page.rs holds it against the native command the link was made from.
export function runLink(mirador, params) {
  const name = params.get("capture");
  window.miradorScreenshot = async (shot, png, view) => {
    await post(`/capture/${shot}`, png, view);
    await post("/capture/done", "done");
  };
  // The first problem is the cause (a device the browser took away); what fails after it, its effect.
  let failed = false;
  window.miradorError = (text) => {
    if (!failed) post("/capture/failed", text);
    failed = true;
  };
  const traced = ["traced", "split", "difference"].includes(params.get("view"));
  const steps = ["overlay off", "panel off", "wait 2s", ...(traced ? ["wait traced", "wait 1s"] : []), `screenshot ${name}.png`];
  for (const step of steps) mirador.step(step);
}
