#!/usr/bin/env python3
"""Serves Mirador's built page (web/build.sh) on localhost: `web/serve.sh` for people,
`web/test.sh` for the browser test, which also passes --capture DIR: then `POST /capture/NAME`
stores the request's body as DIR/NAME and its X-View header (the 3D view's rectangle) as
DIR/NAME.view, which is how the page under test hands over its screenshots."""

import argparse
import functools
import http.server
import pathlib


class Handler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm", ".js": "text/javascript"}
    capture = None

    def do_POST(self):
        name = self.path.removeprefix("/capture/")
        if self.capture is None or name == self.path or "/" in name or name.startswith("."):
            self.send_error(404)
            return
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        (self.capture / name).write_bytes(body)
        if "X-View" in self.headers:
            (self.capture / f"{name}.view").write_text(self.headers["X-View"])
        self.send_response(204)
        self.end_headers()

    def log_message(self, format, *args):
        if self.capture is None:
            super().log_message(format, *args)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--root", default="web/dist", help="the built page's folder")
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--capture", type=pathlib.Path, help="store the page's POSTed screenshots here")
    args = parser.parse_args()
    Handler.capture = args.capture
    handler = functools.partial(Handler, directory=args.root)
    with http.server.ThreadingHTTPServer(("127.0.0.1", args.port), handler) as server:
        print(f"Mirador's page: http://localhost:{args.port}/", flush=True)
        server.serve_forever()


if __name__ == "__main__":
    main()
