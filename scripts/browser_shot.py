#!/usr/bin/env python3
"""Screenshots of a web page as a student's browser shows it: headless Chromium (Debian's
package, installed by scripts/setup.sh) with software WebGL (SwiftShader), driven
over the DevTools protocol with the standard library only (no pip package).

    scripts/browser_shot.py URL OUT.png [--size 1280x720] [--wait 20] [--shots 1] [--every 5]
        [--press KEYS] [--state OUT.json] [--eval EXPRESSION]

Opens URL, waits --wait seconds (the Rerun web viewer compiles 42 MB of WebAssembly first),
then writes --shots screenshots --every seconds apart: OUT.png, or OUT-1.png, OUT-2.png, ...
when there are several, all of the one page kept open (the first captured, the others taken
from the page's screencast, the frames it streams as it repaints). The page's errors (console errors, uncaught exceptions) are printed to stderr. Exit 0 when every
screenshot was written. --press types KEYS (letters and digits) into the page after --wait,
then waits --every before the screenshots. --state writes, once the screenshots are taken, the
app's state as hox's page publishes it (window.hox_state), the page's errors and, with --eval,
the value of EXPRESSION (awaited if it is a promise; the page's module is window.hox). A first capture that gets no answer within BROWSER_SHOT_CAPTURE_SECS
(default 30) is taken from the screencast too."""

import argparse
import base64
import json
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request


class WebSocket:
    """The client side of RFC 6455, text frames only: what the DevTools protocol needs."""

    def __init__(self, url):
        assert url.startswith("ws://")
        host_port, path = url[5:].split("/", 1)
        host, port = host_port.split(":")
        self.sock = socket.create_connection((host, int(port)), timeout=120)
        key = base64.b64encode(os.urandom(16)).decode()
        request = (
            f"GET /{path} HTTP/1.1\r\nHost: {host_port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n"
        )
        self.sock.sendall(request.encode())
        response = b""
        while b"\r\n\r\n" not in response:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise RuntimeError("the browser closed the DevTools connection")
            response += chunk
        if b" 101 " not in response.split(b"\r\n")[0]:
            raise RuntimeError(f"DevTools handshake refused: {response[:200]!r}")
        self.buffer = response.split(b"\r\n\r\n", 1)[1]

    def send(self, text):
        data = text.encode()
        header = bytes([0x81])
        n = len(data)
        if n < 126:
            header += bytes([0x80 | n])
        elif n < 65536:
            header += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            header += bytes([0x80 | 127]) + struct.pack(">Q", n)
        mask = os.urandom(4)
        self.sock.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def _frame(self):
        """One whole frame from the buffer (reading more as needed), or raises the socket's
        timeout with the buffer intact: a wait that times out mid-frame loses nothing."""
        while True:
            b = self.buffer
            if len(b) >= 2:
                n, at = b[1] & 0x7F, 2
                if n == 126 and len(b) >= 4:
                    n, at = struct.unpack(">H", b[2:4])[0], 4
                elif n == 127 and len(b) >= 10:
                    n, at = struct.unpack(">Q", b[2:10])[0], 10
                if (b[1] & 0x7F) < 126 or at > 2:
                    if len(b) >= at + n:
                        self.buffer = b[at + n :]
                        return b[0], b[at : at + n]
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                raise RuntimeError("the browser closed the DevTools connection")
            self.buffer += chunk

    def recv(self):
        message = b""
        while True:
            b0, payload = self._frame()
            opcode = b0 & 0x0F
            if opcode == 0x8:
                raise RuntimeError("the browser closed the DevTools connection")
            if opcode in (0x9, 0xA):
                continue
            message += payload
            if b0 & 0x80:
                return message.decode()


class CallTimeout(Exception):
    """A DevTools call that got no answer in time."""


class Page:
    def __init__(self, ws):
        self.ws = ws
        self.next_id = 0
        # the screencast's frames: the latest one's PNG bytes and how many have come
        self.frame = None
        self.frames = 0
        # (folder, start time) where every frame is also written (--frames)
        self.keep_frames = None

    def call(self, method, timeout=120.0, **params):
        """Sends `method` and returns its answer, noting the events that come before it;
        raises CallTimeout when no answer comes within `timeout` seconds (an answer that
        comes later is read and ignored like any event)."""
        if os.environ.get("BROWSER_SHOT_DEBUG"):
            print(f"{time.strftime('%X')} {method}", file=sys.stderr)
        self.next_id += 1
        # this call's own id: an event noted while waiting may send (an acknowledgement), which
        # takes the next id, and the answer to wait for is still this one
        call_id = self.next_id
        self.ws.send(json.dumps({"id": call_id, "method": method, "params": params}))
        end = time.time() + timeout
        try:
            while True:
                left = end - time.time()
                if left <= 0:
                    raise CallTimeout(f"{method}: no answer in {timeout:.0f} s")
                self.ws.sock.settimeout(left)
                try:
                    msg = json.loads(self.ws.recv())
                except (socket.timeout, TimeoutError):
                    raise CallTimeout(f"{method}: no answer in {timeout:.0f} s") from None
                if msg.get("id") == call_id:
                    if "error" in msg:
                        raise RuntimeError(f"{method}: {msg['error']}")
                    return msg.get("result", {})
                self.note(msg)
        finally:
            self.ws.sock.settimeout(120)

    def send(self, method, **params):
        """A call whose answer is not waited for (read later and ignored)."""
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))

    def note(self, msg):
        method = msg.get("method", "")
        if method == "Page.screencastFrame":
            self.frame = base64.b64decode(msg["params"]["data"])
            self.frames += 1
            if self.keep_frames:
                folder, start = self.keep_frames
                with open(os.path.join(folder, f"frame-{time.time() - start:07.3f}.png"), "wb") as f:
                    f.write(self.frame)
            self.send("Page.screencastFrameAck", sessionId=msg["params"]["sessionId"])

    def sleep(self, secs):
        """Waits, reading the events meanwhile (a pause in the protocol stalls nothing)."""
        end = time.time() + secs
        while time.time() < end:
            self.ws.sock.settimeout(max(0.05, end - time.time()))
            try:
                self.note(json.loads(self.ws.recv()))
            except (socket.timeout, TimeoutError):
                pass
        self.ws.sock.settimeout(120)


def next_screencast_frame(page, width, height, streaming):
    """The first frame the page's screencast streams after this call (starting the screencast
    unless `streaming`), the page nudged to repaint by pointer moves over its top bar."""
    if not streaming:
        page.call("Page.startScreencast", format="png", maxWidth=width, maxHeight=height)
    seen = page.frames
    end = time.time() + 90
    while page.frames == seen and time.time() < end:
        for x in (width // 2, width // 2 + 1):
            page.send("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=14)
        page.sleep(1.0)
    if page.frames == seen:
        sys.exit("browser_shot: no new frame of the page in 90 s")
    return page.frame


# Run in the page before its own scripts: keeps its console errors, uncaught exceptions and
# unhandled rejections in a list read at the end (page_errors), each still reaching the console.
PAGE_ERRORS = """(() => {
  const errors = [];
  window.__hox_page_errors = errors;
  const error = console.error.bind(console);
  console.error = (...args) => { errors.push(args.map(String).join(" ")); error(...args); };
  addEventListener("error", (e) => errors.push(e.message || String(e.error)));
  addEventListener("unhandledrejection", (e) => errors.push("unhandled rejection: " + String(e.reason)));
})();"""


def page_errors(page):
    """The errors PAGE_ERRORS kept (none if the page never ran it)."""
    try:
        result = page.call("Runtime.evaluate", timeout=30,
                           expression="JSON.stringify(window.__hox_page_errors || [])", returnByValue=True)
        return json.loads(result.get("result", {}).get("value") or "[]")
    except (CallTimeout, RuntimeError, ValueError) as e:
        return [f"the page's errors could not be read: {e}"]


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    sys.exit("browser_shot: no Chromium found (scripts/setup.sh installs Debian's)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("url")
    ap.add_argument("out")
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--wait", type=float, default=20.0)
    ap.add_argument("--shots", type=int, default=1)
    ap.add_argument("--every", type=float, default=5.0)
    ap.add_argument("--frames", help="also keep every frame the page paints from the moment it is "
                    "opened, as DIR/frame-SECONDS.png (seconds since the page was asked for)")
    ap.add_argument("--press", default="", help="keys typed into the page after --wait")
    ap.add_argument("--state", help="write the page's state, errors and --eval's value here (JSON)")
    ap.add_argument("--eval", help="a JavaScript expression evaluated at the end (with --state)")
    args = ap.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    # how long the first picture's capture may take before the screencast stands in
    # (an environment variable so that the fallback itself can be tried)
    try:
        capture_secs = float(os.environ.get("BROWSER_SHOT_CAPTURE_SECS", "30"))
    except ValueError:
        sys.exit("browser_shot: BROWSER_SHOT_CAPTURE_SECS must be a number of seconds, "
                 f"not {os.environ['BROWSER_SHOT_CAPTURE_SECS']!r}")
    if not capture_secs > 0:
        sys.exit(f"browser_shot: BROWSER_SHOT_CAPTURE_SECS must be positive, not {capture_secs}")
    profile = tempfile.mkdtemp(prefix="hox-chromium-")
    browser = subprocess.Popen(
        [
            chromium(),
            "--headless=new",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--no-first-run",
            "--disable-extensions",
            "--remote-debugging-port=0",
            f"--user-data-dir={profile}",
            f"--window-size={width},{height}",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        port_file = os.path.join(profile, "DevToolsActivePort")
        for _ in range(300):
            if os.path.exists(port_file) and open(port_file).read().count("\n") >= 1:
                break
            time.sleep(0.1)
        else:
            sys.exit("browser_shot: Chromium did not start its DevTools server")
        port = open(port_file).read().split("\n")[0].strip()
        targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list"))
        page_target = next(t for t in targets if t.get("type") == "page")
        page = Page(WebSocket(page_target["webSocketDebuggerUrl"]))
        # the page's errors are noted by the page itself (PAGE_ERRORS) and read at the end: the
        # DevTools console (Runtime.enable) would make the browser serialise and send every
        # console message as it comes, and the web viewer writes about 20,000 debug lines
        # while it compiles its shaders, which kept the page from painting for seconds: a cost
        # a student's browser, with no DevTools attached, does not pay
        page.call("Page.enable")
        page.call("Page.addScriptToEvaluateOnNewDocument", source=PAGE_ERRORS)
        page.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)
        streaming = args.frames is not None
        if args.frames:
            os.makedirs(args.frames, exist_ok=True)
            page.keep_frames = (args.frames, time.time())
            page.call("Page.startScreencast", format="png", maxWidth=width, maxHeight=height)
        page.call("Page.navigate", url=args.url)
        page.sleep(args.wait)
        if args.press:
            for ch in args.press:
                key = {"type": "keyDown", "key": ch.lower(), "text": ch.lower(),
                       "code": ("Key" + ch.upper()) if ch.isalpha() else ("Digit" + ch),
                       "windowsVirtualKeyCode": ord(ch.upper())}
                page.call("Input.dispatchKeyEvent", **key)
                page.call("Input.dispatchKeyEvent", **dict(key, type="keyUp", text=""))
            page.sleep(args.every)
        base, ext = os.path.splitext(args.out)
        for k in range(args.shots):
            if k > 0:
                page.sleep(args.every)
                # Page.captureScreenshot of a page that repaints continuously in software WebGL
                # returns once and then never again: the later pictures of the same open page
                # are frames its screencast streams (each acknowledged as it comes), the first
                # one painted after this picture was asked for
                path = f"{base}-{k + 1}{ext}"
                with open(path, "wb") as f:
                    f.write(next_screencast_frame(page, width, height, True))
                print(path)
                continue
            # the viewer paints only when something changes: a pointer move over the empty
            # middle of its top bar makes it paint now, so the capture has a frame to take
            for x in (width // 2, width // 2 + 1):
                page.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=14)
            path = args.out if args.shots == 1 else f"{base}-{k + 1}{ext}"
            try:
                png = base64.b64decode(page.call("Page.captureScreenshot", timeout=capture_secs, format="png")["data"])
            except CallTimeout as e:
                # seen in CI once (a page opened while the app streams, software WebGL): the
                # capture never answers; the page's screencast still streams its frames
                print(f"browser_shot: {e}; taking the picture from the page's screencast", file=sys.stderr)
                png = next_screencast_frame(page, width, height, streaming)
                streaming = True
            with open(path, "wb") as f:
                f.write(png)
            print(path)
            if args.shots > 1 and not streaming:
                streaming = True
                page.call("Page.startScreencast", format="png", maxWidth=width, maxHeight=height)
        errors = page_errors(page)
        for e in errors:
            print(f"browser_shot: page error: {e}", file=sys.stderr)
        if args.state:
            state = {"errors": errors}
            result = page.call("Runtime.evaluate", timeout=60, expression="window.hox_state || null",
                               returnByValue=True)
            text = result.get("result", {}).get("value")
            state["state"] = json.loads(text) if text else None
            if args.eval:
                result = page.call("Runtime.evaluate", timeout=1200, expression=args.eval,
                                   awaitPromise=True, returnByValue=True)
                if "exceptionDetails" in result:
                    state["eval_error"] = json.dumps(result["exceptionDetails"])[:2000]
                state["eval"] = result.get("result", {}).get("value")
            with open(args.state, "w") as f:
                json.dump(state, f, indent=1)
    finally:
        browser.terminate()
        try:
            browser.wait(10)
        except subprocess.TimeoutExpired:
            browser.kill()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    main()
