#!/usr/bin/env python3
"""tests/viewer/range_server.py (Range, --rate throttling, --die-after, --stall-after, ...) with CORS headers,
for the web page's tests: the page comes from nginx on one port, the pack from this server on another, so the
browser needs Access-Control-Allow-Origin and, for Content-Range/Content-Length to be readable, Expose-Headers.
Same options as range_server.py; prints "PORT <n>" once listening."""
import os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "viewer"))
import range_server  # noqa: E402

_end_headers = range_server.Handler.end_headers


def end_headers(self):
    self.send_header("Access-Control-Allow-Origin", "*")
    self.send_header("Access-Control-Expose-Headers", "Content-Range, Content-Length, Accept-Ranges")
    _end_headers(self)


def do_OPTIONS(self):  # CORS preflight (a Range header that is not a single simple range needs one)
    self.send_response(204)
    self.send_header("Access-Control-Allow-Methods", "GET, HEAD, OPTIONS")
    self.send_header("Access-Control-Allow-Headers", "Range")
    self.send_header("Access-Control-Max-Age", "86400")
    self.send_header("Content-Length", "0")
    self.end_headers()


range_server.Handler.end_headers = end_headers
range_server.Handler.do_OPTIONS = do_OPTIONS

if __name__ == "__main__":
    range_server.main()
