// The page's tracer worker (src/web/tracer.rs, src/viewer/traced/pool.rs): the module the page
// loaded (`?module=`), without a window. It is given a job (the scene as the page has it, and the
// files the person opened), then rows of the full image, and posts back their pixels, encoded for
// display; or a terms job (the raster frame's scene), then the hybrid's terms of a view's rows,
// and posts back their header and numbers.
import { fetchAssets } from "./files.js";

const module = new URL(self.location.href).searchParams.get("module") ?? "mirador.js";
const ready = import(`./${module}`).then(async (mirador) => {
  await mirador.default();
  await fetchAssets(mirador);
  return mirador;
});
self.onmessage = async (event) => {
  const message = event.data;
  try {
    const mirador = await ready;
    if (message.files) {
      for (const [name, bytes] of message.files) mirador.add_file(name, bytes);
    }
    if (message.job) mirador.tracer_job(message.job);
    if (message.termsJob) mirador.terms_job(message.termsJob);
    if (message.terms) {
      const [header, values] = mirador.trace_terms(message.terms);
      self.postMessage({ key: message.key, header, values }, [values.buffer]);
    }
    if (message.rows) {
      const [first, end] = message.rows;
      const pixels = mirador.trace_rows(first, end);
      self.postMessage({ key: message.key, first, pixels }, [pixels.buffer]);
    }
  } catch (error) {
    self.postMessage({ key: message.key, error: String(error) });
  }
};
