#!/usr/bin/env python3
"""A small HTTP/1.1 file server with Range requests, for the geomip-view streaming tests.

Python's http.server ignores Range headers; this one answers them (206 + Content-Range). Options:
  --rate BYTES_PER_S   throttle every response body (sleeps between 4 KiB blocks)
  --no-ranges          ignore Range headers, like Python's http.server (200 + the whole file)
  --die-after BYTES    after sending this many body bytes in total, drop the connection mid-body and exit
                       (the server "killed mid-stream")
  --endless            no Content-Length; after the file (or the asked range) keep sending zero bytes, up to
                       --endless-cap bytes (default 1 GiB) per response, as a server that never ends its body
  --stall-after BYTES  after sending this many body bytes in total, keep the connection open and send nothing
                       (for at most --stall-seconds, default 120)
  --request-log FILE   append one line per request ("GET <path> <Range or ->") to FILE
  --no-length          no Content-Length header (the body ends when the connection closes)
Paths: /redirect/N/NAME answers 302 to /redirect/N-1/NAME (N = 0: to /NAME); /loop/NAME answers 302 to
itself forever (the client must give up). Every loop here is bounded; it listens on 127.0.0.1 only.
It prints "PORT <n>" on stdout once listening (port 0 = any free port).
"""
import argparse, os, re, sys, time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

args = None
sent_total = 0


class Handler(BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"

    def log_message(self, *a):
        pass

    def redirect(self, location):
        self.send_response(302)
        self.send_header("Location", location)
        self.send_header("Content-Length", "0")
        self.end_headers()

    def do_GET(self):
        global sent_total
        if args.request_log:
            with open(args.request_log, "a") as log:
                log.write("GET %s %s\n" % (self.path, self.headers.get("Range", "-")))
        m = re.match(r"/redirect/(\d+)/(.+)$", self.path)
        if m:
            n = int(m.group(1))
            return self.redirect("/%s" % m.group(2) if n == 0 else "/redirect/%d/%s" % (n - 1, m.group(2)))
        if self.path.startswith("/loop/"):
            return self.redirect(self.path)
        path = os.path.join(args.root, self.path.lstrip("/").split("?")[0])
        if not os.path.isfile(path):
            self.send_response(404)
            self.send_header("Content-Length", "0")
            self.end_headers()
            return
        size = os.path.getsize(path)
        begin, end = 0, size - 1
        m = None if args.no_ranges else re.match(r"bytes=(\d+)-(\d*)$", self.headers.get("Range", ""))
        if m:
            begin = int(m.group(1))
            end = min(int(m.group(2)), size - 1) if m.group(2) else size - 1
            if begin >= size or begin > end:
                self.send_response(416)
                self.send_header("Content-Range", "bytes */%d" % size)
                self.send_header("Content-Length", "0")
                self.end_headers()
                return
            self.send_response(206)
            self.send_header("Content-Range", "bytes %d-%d/%d" % (begin, end, size))
        else:
            self.send_response(200)
        if args.endless or args.no_length:
            self.send_header("Connection", "close")
            self.close_connection = True
        else:
            self.send_header("Content-Length", str(end - begin + 1))
        self.send_header("Accept-Ranges", "bytes")
        self.end_headers()
        with open(path, "rb") as f:
            f.seek(begin)
            left = end - begin + 1
            start = time.monotonic()
            done = 0
            while left > 0:
                block = f.read(min(4096, left))
                if args.die_after is not None and sent_total + len(block) > args.die_after:
                    keep = max(0, args.die_after - sent_total)
                    self.wfile.write(block[:keep])
                    self.wfile.flush()
                    os._exit(0)  # killed mid-stream: the socket closes with the body incomplete
                if args.stall_after is not None and sent_total + len(block) > args.stall_after:
                    keep = max(0, args.stall_after - sent_total)
                    self.wfile.write(block[:keep])
                    self.wfile.flush()
                    sent_total += keep
                    time.sleep(args.stall_seconds)  # stalled: the connection stays open, nothing arrives
                    return
                self.wfile.write(block)
                left -= len(block)
                done += len(block)
                sent_total += len(block)
                if args.rate:
                    delay = start + done / args.rate - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)
            if args.endless:  # never end the body (bounded by --endless-cap and by the client hanging up)
                zeros = bytes(65536)
                extra = 0
                try:
                    while extra < args.endless_cap:
                        self.wfile.write(zeros)
                        extra += len(zeros)
                except (BrokenPipeError, ConnectionResetError):
                    pass


class Server(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address):
        if not isinstance(sys.exc_info()[1], (ConnectionError, BrokenPipeError)):  # a client hanging up is normal
            super().handle_error(request, client_address)


def main():
    global args
    p = argparse.ArgumentParser()
    p.add_argument("--root", required=True)
    p.add_argument("--port", type=int, default=0)
    p.add_argument("--rate", type=float, default=0)
    p.add_argument("--die-after", type=int, default=None)
    p.add_argument("--no-ranges", action="store_true", help="ignore Range headers (answer 200, whole file)")
    p.add_argument("--endless", action="store_true", help="never end a body (no Content-Length, zero padding)")
    p.add_argument("--endless-cap", type=int, default=1 << 30)
    p.add_argument("--stall-after", type=int, default=None)
    p.add_argument("--stall-seconds", type=float, default=120)
    p.add_argument("--request-log", default=None)
    p.add_argument("--no-length", action="store_true", help="no Content-Length (body ends at connection close)")
    args = p.parse_args()
    server = Server(("127.0.0.1", args.port), Handler)
    print("PORT %d" % server.server_address[1], flush=True)
    server.serve_forever()


if __name__ == "__main__":
    main()
