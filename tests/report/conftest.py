"""Headless Chromium driven over the Chrome DevTools Protocol, for the report tests.

A tiny standard-library WebSocket client (RFC 6455: masked client frames,
text frames, fragmentation, ping) talks CDP to Debian's ``chromium`` started
with ``--remote-debugging-port=0``; the port is read from the
``DevToolsActivePort`` file Chromium writes into its user-data directory.

:meth:`Browser.render` loads a page and returns what a person would notice:
console errors, uncaught exceptions, log-domain errors, requests to anything
but the page itself and ``data:`` URIs, and the state of every ``<img>``.
Chromium is a CI requirement (``.ci/run`` installs it), so a missing binary
fails the tests with a clear message instead of skipping them.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import socket
import struct
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

import pytest

CHROMIUM = os.environ.get("CLUTCHLAB_CHROMIUM", "/usr/bin/chromium")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--disable-extensions", "--mute-audio"]


class WebSocket:
    """Minimal blocking WebSocket client (text frames only), enough for CDP on localhost."""

    def __init__(self, url: str, timeout: float = 30.0):
        assert url.startswith("ws://"), url
        hostport, _, path = url[5:].partition("/")
        host, _, port = hostport.partition(":")
        self.sock = socket.create_connection((host, int(port)), timeout=timeout)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /{path} HTTP/1.1\r\nHost: {hostport}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError("websocket handshake: connection closed")
            head += chunk
        status = head.split(b"\r\n", 1)[0]
        if b" 101 " not in status:
            raise ConnectionError(f"websocket handshake refused: {status!r}")
        self.buffer = head.split(b"\r\n\r\n", 1)[1]

    def _exact(self, n: int) -> bytes:
        while len(self.buffer) < n:
            chunk = self.sock.recv(max(65536, n - len(self.buffer)))
            if not chunk:
                raise ConnectionError("websocket closed by the browser")
            self.buffer += chunk
        out, self.buffer = self.buffer[:n], self.buffer[n:]
        return out

    def _send_frame(self, opcode: int, payload: bytes) -> None:
        mask = os.urandom(4)
        n = len(payload)
        if n < 126:
            header = struct.pack("!BB", 0x80 | opcode, 0x80 | n)
        elif n < 65536:
            header = struct.pack("!BBH", 0x80 | opcode, 0x80 | 126, n)
        else:
            header = struct.pack("!BBQ", 0x80 | opcode, 0x80 | 127, n)
        masked = bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
        self.sock.sendall(header + mask + masked)

    def send(self, text: str) -> None:
        self._send_frame(0x1, text.encode("utf-8"))

    def recv(self) -> str:
        message = b""
        while True:
            b0, b1 = self._exact(2)
            opcode, n = b0 & 0x0F, b1 & 0x7F
            if n == 126:
                n = struct.unpack("!H", self._exact(2))[0]
            elif n == 127:
                n = struct.unpack("!Q", self._exact(8))[0]
            mask = self._exact(4) if b1 & 0x80 else None
            payload = self._exact(n)
            if mask:
                payload = bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
            if opcode == 0x9:  # ping
                self._send_frame(0xA, payload)
                continue
            if opcode == 0x8:
                raise ConnectionError("websocket closed by the browser")
            if opcode in (0x0, 0x1, 0x2):
                message += payload
                if b0 & 0x80:
                    return message.decode("utf-8")

    def close(self) -> None:
        try:
            self._send_frame(0x8, b"")
        except OSError:
            pass
        self.sock.close()


class Browser:
    """One headless Chromium process; :meth:`render` opens a page in it over CDP."""

    def __init__(self):
        if not (os.path.isfile(CHROMIUM) and os.access(CHROMIUM, os.X_OK)):
            pytest.fail(f"Chromium not found at {CHROMIUM}: install Debian's 'chromium' package "
                        "(.ci/run does so when it is absent); the report tests need a real browser")
        self.profile = tempfile.mkdtemp(prefix="clutchlab-chromium-")
        self.proc = subprocess.Popen([CHROMIUM, *FLAGS, f"--user-data-dir={self.profile}",
                                      "--remote-debugging-address=127.0.0.1", "--remote-debugging-port=0",
                                      "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = Path(self.profile) / "DevToolsActivePort"
        deadline = time.monotonic() + 30.0
        while not (port_file.exists() and port_file.read_text().count("\n") >= 1):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                pytest.fail(f"Chromium ({CHROMIUM}) did not start its DevTools endpoint")
            time.sleep(0.05)
        self.port = int(port_file.read_text().splitlines()[0])
        self.next_id = 0

    def _page_ws(self) -> str:
        req = urllib.request.Request(f"http://127.0.0.1:{self.port}/json/new?about:blank", method="PUT")
        with urllib.request.urlopen(req, timeout=10) as resp:
            return json.loads(resp.read())["webSocketDebuggerUrl"]

    def render(self, url: str, settle: float = 0.5, timeout: float = 30.0) -> dict:
        """Load ``url`` in a new tab and report errors, requests and images.

        Returns
        -------
        dict
            ``errors`` (console errors, exceptions, log errors: list of str),
            ``requests`` (URLs fetched other than the page and ``data:``),
            ``failed`` (requests that failed), ``images`` (list of
            ``{complete, width, alt}``) and ``title``.
        """
        ws = WebSocket(self._page_ws(), timeout=timeout)
        events: list[dict] = []

        def call(method, **params):
            self.next_id += 1
            my_id = self.next_id
            ws.send(json.dumps({"id": my_id, "method": method, "params": params}))
            while True:
                msg = json.loads(ws.recv())
                if msg.get("id") == my_id:
                    if "error" in msg:
                        raise RuntimeError(f"CDP {method}: {msg['error']}")
                    return msg.get("result", {})
                events.append(msg)

        try:
            for domain in ("Runtime", "Log", "Network", "Page"):
                call(f"{domain}.enable")
            call("Page.navigate", url=url)
            deadline = time.monotonic() + timeout
            while not any(e.get("method") == "Page.loadEventFired" for e in events):
                if time.monotonic() > deadline:
                    raise TimeoutError(f"{url} did not finish loading in {timeout} s")
                events.append(json.loads(ws.recv()))
            # images decode asynchronously: wait for every <img> to settle, then give late errors a moment
            probe = ("Promise.all(Array.from(document.images).map(i => i.decode().catch(() => null)))"
                     ".then(() => JSON.stringify({title: document.title, images: Array.from(document.images)"
                     ".map(i => ({complete: i.complete, width: i.naturalWidth, alt: i.alt}))}))")
            result = call("Runtime.evaluate", expression=probe, awaitPromise=True, returnByValue=True)
            state = json.loads(result["result"]["value"])
            ws.sock.settimeout(settle)
            try:
                while True:
                    events.append(json.loads(ws.recv()))
            except (socket.timeout, TimeoutError):
                pass
        finally:
            ws.close()
        errors, requests, failed = [], [], []
        for e in events:
            method, p = e.get("method"), e.get("params", {})
            if method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errors.append("console: " + " ".join(str(a.get("value", a.get("description", ""))) for a in p["args"]))
            elif method == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                errors.append("exception: " + d.get("exception", {}).get("description", d.get("text", "")))
            elif method == "Log.entryAdded" and p["entry"]["level"] == "error":
                errors.append(f"log ({p['entry'].get('source')}): {p['entry']['text']}")
            elif method == "Network.requestWillBeSent":
                u = p["request"]["url"]
                if not u.startswith("data:") and u != url:
                    requests.append(u)
            elif method == "Network.loadingFailed":
                failed.append(p.get("errorText", "?"))
        return {"errors": errors, "requests": requests, "failed": failed, **state}

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        shutil.rmtree(self.profile, ignore_errors=True)


@pytest.fixture(scope="session")
def browser():
    """A headless Chromium for the whole test session."""
    b = Browser()
    yield b
    b.close()


def page_problems(state: dict, n_figures: int) -> list[str]:
    """What is wrong with a rendered report page (empty list: nothing)."""
    problems = list(state["errors"])
    problems += [f"external request: {u}" for u in state["requests"]]
    problems += [f"failed request: {f}" for f in state["failed"]]
    broken = [i["alt"] for i in state["images"] if not (i["complete"] and i["width"] > 0)]
    problems += [f"broken image: {alt}" for alt in broken]
    if len(state["images"]) != n_figures:
        problems.append(f"{len(state['images'])} images on the page for {n_figures} figures")
    return problems


@pytest.fixture(scope="session")
def check_page():
    """:func:`page_problems` as a fixture (test modules cannot import conftest)."""
    return page_problems
