#!/usr/bin/env python3
"""Serves a folder on 127.0.0.1 as a static host must serve the page: every response carries
Cross-Origin-Opener-Policy: same-origin and Cross-Origin-Embedder-Policy: require-corp, which
make the page cross-origin isolated (SharedArrayBuffer, so the threaded WebAssembly build).
--no-isolation leaves the two headers out (the page then runs its single-thread build).
Standard library only."""

import argparse
import functools
import http.server


class Handler(http.server.SimpleHTTPRequestHandler):
    """SimpleHTTPRequestHandler plus the isolation headers (when `isolated`)."""

    isolated = True

    def end_headers(self):
        if self.isolated:
            self.send_header("Cross-Origin-Opener-Policy", "same-origin")
            self.send_header("Cross-Origin-Embedder-Policy", "require-corp")
        super().end_headers()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("port", type=int)
    ap.add_argument("--directory", required=True)
    ap.add_argument("--bind", default="127.0.0.1")
    ap.add_argument("--no-isolation", action="store_true", help="leave out COOP/COEP")
    a = ap.parse_args()
    handler = type("H", (Handler,), {"isolated": not a.no_isolation})
    server = http.server.ThreadingHTTPServer((a.bind, a.port), functools.partial(handler, directory=a.directory))
    print(f"serving {a.directory} on http://{a.bind}:{a.port}/ ({'isolated' if handler.isolated else 'not isolated'})", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
