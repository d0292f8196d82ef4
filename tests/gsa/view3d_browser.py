#!/usr/bin/env python3
"""Opens gsa's 3-D view (view.html or report.html) in headless Chromium and checks it.

    view3d_browser.py PAGE.html [--shots DIR] [--chromium PATH]

Drives Chromium over the DevTools protocol on a pipe (--remote-debugging-pipe; Python's
standard library only) with software WebGL (SwiftShader):
  - the page loads with no console error and no uncaught exception, and the view says
    data-state="ready";
  - the WebGL canvas is not blank: at least 50 distinct colours inside it;
  - after gsaView.rotate(30) the canvas differs from the first screenshot;
  - a click on the part opens the read-out with the surface's values and the nearest mark;
  - switching the colour to a strains.csv column and to the undeformed surface redraws.
Exit 0: passed; 1: failed (the reason on stderr); 77: no Chromium here (ctest SKIP).
"""

import argparse
import base64
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

SKIP = 77


def decode_png(data):
    """RGB(A) 8-bit PNG to (width, height, channels, rows of bytes)."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            width, height, depth, ctype = struct.unpack(">IIBB", body[:10])
            if depth != 8 or ctype not in (2, 6):
                raise ValueError("PNG colour type %d depth %d not handled" % (ctype, depth))
            channels = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev, p = [], bytearray(stride), 0
    for _ in range(height):
        f, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
        p += 1 + stride
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def region(png, rect):
    """Pixels (r, g, b) inside rect = (x, y, w, h) in CSS pixels (device scale 1)."""
    width, height, ch, rows = png
    x0, y0 = max(0, int(rect[0])), max(0, int(rect[1]))
    x1, y1 = min(width, int(rect[0] + rect[2])), min(height, int(rect[1] + rect[3]))
    return [rows[y][x * ch:x * ch + 3] for y in range(y0, y1) for x in range(x0, x1)]


class Browser:
    def __init__(self, chromium, profile):
        r1, w1 = os.pipe()  # to Chromium (its fd 3)
        r2, w2 = os.pipe()  # from Chromium (its fd 4)

        def child_fds():  # Chromium reads fd 3 and writes fd 4
            a, b = os.dup(r1), os.dup(w2)
            os.dup2(a, 3)
            os.dup2(b, 4)

        args = [chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                "--remote-debugging-pipe", "--no-first-run", "--disable-extensions", "--hide-scrollbars",
                "--user-data-dir=" + profile, "--window-size=1200,900", "about:blank"]
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL, preexec_fn=child_fds, pass_fds=(3, 4))
        os.close(r1)
        os.close(w2)
        self.out, self.inp = os.fdopen(w1, "wb"), os.fdopen(r2, "rb")
        self.next_id, self.buffer, self.events = 0, b"", []
        self.session = None
        self.raw = []  # every screenshot's PNG bytes

    def _read(self, deadline):
        while b"\0" not in self.buffer:
            if time.time() > deadline:
                raise TimeoutError("no answer from Chromium")
            chunk = os.read(self.inp.fileno(), 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the pipe (crashed?)")
            self.buffer += chunk
        msg, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method, params=None, session=True, timeout=120):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        self.out.write(json.dumps(msg).encode() + b"\0")
        self.out.flush()
        deadline = time.time() + timeout
        while True:
            m = self._read(deadline)
            if m.get("id") == self.next_id:
                if "error" in m:
                    raise RuntimeError("%s: %s" % (method, m["error"]))
                return m.get("result", {})
            if "method" in m:
                self.events.append(m)

    def wait_event(self, method, timeout=120):
        deadline = time.time() + timeout
        while True:
            for k, e in enumerate(self.events):
                if e["method"] == method:
                    return self.events.pop(k)
            self.events.append(self._read(deadline))

    def evaluate(self, expr):
        r = self.call("Runtime.evaluate", {"expression": expr, "returnByValue": True, "awaitPromise": True})
        if "exceptionDetails" in r:
            raise RuntimeError("%s: %s" % (expr, r["exceptionDetails"].get("text")))
        return r["result"].get("value")

    def screenshot(self):
        png = base64.b64decode(self.call("Page.captureScreenshot", {"format": "png"})["data"])
        self.raw.append(png)
        return decode_png(png)

    def close(self):
        try:
            self.call("Browser.close", session=False, timeout=10)
        except Exception:
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def problems_in(events):
    """Console errors and uncaught exceptions among the events so far."""
    out = []
    for e in events:
        p = e.get("params", {})
        if e["method"] == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            out.append("uncaught: " + (d.get("exception", {}).get("description") or d.get("text", "")))
        elif e["method"] == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            out.append("console.error: " + " ".join(str(a.get("value", a.get("description", ""))) for a in p["args"]))
        elif e["method"] == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            out.append("log: " + p["entry"].get("text", ""))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("page")
    ap.add_argument("--shots", help="folder to keep the screenshots in")
    ap.add_argument("--chromium", default=None)
    a = ap.parse_args()
    chromium = a.chromium or shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("SKIP: no chromium here (Debian package chromium; scripts/install_deps.sh installs it)")
        return SKIP
    if not os.path.isfile(a.page):
        print("FAIL: %s: no such page" % a.page, file=sys.stderr)
        return 1
    url = "file://" + os.path.abspath(a.page)
    t0 = time.time()
    profile = tempfile.mkdtemp(prefix="gsa-view-test-")
    b = Browser(chromium, profile)
    failures = []
    try:
        targets = b.call("Target.getTargets", session=False)["targetInfos"]
        page = [t for t in targets if t["type"] == "page"]
        target = page[0]["targetId"] if page else b.call("Target.createTarget", {"url": "about:blank"},
                                                           session=False)["targetId"]
        b.session = b.call("Target.attachToTarget", {"targetId": target, "flatten": True}, session=False)["sessionId"]
        for m in ("Runtime.enable", "Page.enable", "Log.enable"):
            b.call(m)
        b.call("Emulation.setDeviceMetricsOverride", {"width": 1200, "height": 900, "deviceScaleFactor": 1,
                                                       "mobile": False})
        b.call("Page.navigate", {"url": url})
        b.wait_event("Page.loadEventFired")
        state = None
        deadline = time.time() + 60
        while time.time() < deadline:
            state = b.evaluate("(function(){var r=document.getElementById('gsa-view');"
                               "return r ? r.dataset.state + '|' + (r.dataset.error || '') : 'absent|';})()")
            if not state.startswith("loading"):
                break
            time.sleep(0.2)
        print("page %s loaded in %.1f s: state %s" % (os.path.basename(a.page), time.time() - t0, state))
        if not state or not state.startswith("ready"):
            failures.append("the view is not ready: " + str(state))
        else:
            b.evaluate("document.getElementById('gsa-view').scrollIntoView()")
            rect = b.evaluate("(function(){var c=document.querySelector('#gsa-view canvas.gv-gl');"
                              "var r=c.getBoundingClientRect();return [r.left,r.top,r.width,r.height];})()")
            shot0 = b.screenshot()
            px0 = region(shot0, rect)
            colours = len(set(px0))
            print("canvas %dx%d at (%d, %d): %d distinct colours" % (rect[2], rect[3], rect[0], rect[1], colours))
            if colours < 50:
                failures.append("the canvas looks blank: %d distinct colours" % colours)
            b.evaluate("gsaView.rotate(30)")
            shot1 = b.screenshot()
            px1 = region(shot1, rect)
            changed = sum(1 for p, q in zip(px0, px1) if p != q)
            print("after rotating 30 deg: %d of %d canvas pixels changed (%.1f %%)"
                  % (changed, len(px0), 100.0 * changed / max(1, len(px0))))
            if changed < 0.01 * len(px0):
                failures.append("the rotated view does not differ from the first (%d pixels)" % changed)
            # A click at the canvas centre (the part is centred) opens the read-out.
            cx, cy = rect[0] + rect[2] / 2, rect[1] + rect[3] / 2
            for kind in ("mousePressed", "mouseReleased"):
                b.call("Input.dispatchMouseEvent", {"type": kind, "x": cx, "y": cy, "button": "left", "clickCount": 1})
            info = b.evaluate("(function(){var i=document.querySelector('#gsa-view .gv-info');"
                              "return i.style.display + '|' + i.textContent;})()")
            b.screenshot()  # kept with --shots: the read-out
            print("click read-out: %s" % info[:300])
            if not info.startswith("block") or "Surface at" not in info:
                failures.append("a click on the part gave no read-out: " + info[:200])
            # Another field (a strains.csv column when there is one) and the undeformed blank.
            b.evaluate("(function(){var s=document.querySelector('#gsa-view .gv-bar select');"
                       "s.value=String(s.options.length-1);s.dispatchEvent(new Event('change'));"
                       "var t=document.querySelectorAll('#gsa-view .gv-bar select')[1];"
                       "t.value='u';t.dispatchEvent(new Event('change'));})()")
            shot2 = b.screenshot()
            px2 = region(shot2, rect)
            changed2 = sum(1 for p, q in zip(px1, px2) if p != q)
            print("other field on the undeformed surface: %d pixels changed" % changed2)
            if changed2 < 0.01 * len(px0):
                failures.append("switching field and surface did not redraw")
            if a.shots:
                os.makedirs(a.shots, exist_ok=True)
                stem = os.path.splitext(os.path.basename(a.page))[0]
                names = ("first", "rotated", "clicked", "undeformed_last_field")
                for name, png in zip(names, b.raw):
                    with open(os.path.join(a.shots, "%s_%s.png" % (stem, name)), "wb") as f:
                        f.write(png)
        time.sleep(0.3)
        b.call("Runtime.evaluate", {"expression": "1"})  # collect late events
        failures += problems_in(b.events)
    except Exception as e:  # noqa: BLE001 - any failure of the browser run is a test failure
        failures.append("browser run failed: %s" % e)
    finally:
        b.close()
        shutil.rmtree(profile, ignore_errors=True)
    print("browser checks took %.1f s" % (time.time() - t0))
    if failures:
        for f in failures:
            print("FAIL: " + f, file=sys.stderr)
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
