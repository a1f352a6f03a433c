// The files the page fetches beside its module rather than carrying them (src/files.rs,
// `FETCHED`: the phantom volume, the teapot), at their paths relative to the page. The page and
// each tracer worker fetch them once their module has started (the browser's cache serves the
// workers), and add them where the scenes that name them look.
export async function fetchAssets(mirador) {
  await Promise.all(mirador.fetched_files().map(async (path) => {
    const response = await fetch(path);
    if (!response.ok) throw new Error(`${path}: ${response.status} ${response.statusText}`);
    mirador.add_asset(path, new Uint8Array(await response.arrayBuffer()));
  }));
}
