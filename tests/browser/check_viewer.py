#!/usr/bin/env python3
"""Checks a `report.html` written by `cdyn run --html` in headless Chromium.

Usage: check_viewer.py REPORT_HTML [--also REPORT_HTML[#fragment]]... [--spatial REPORT_HTML]...
                       [--screenshot OUT_PNG] [--screenshot-3d OUT_PNG]

REPORT_HTML is a planar mechanism's page; pages given with --also (a
compare's, a model without a drawing) get the first two checks below;
spatial runs' pages (--spatial) get all of them, and besides: orbiting
(`#yaw=60&pitch=20&zoom=1.5`) changes the view and the scene's pixels at
the same instant, and playing (no `#pos`; on a manual clock, `#clock=N`)
advances the animation's frame to the time played.

Standard library only; Chromium is driven from its command line:
  * the page at two slider positions (`#pos=0`, `#pos=0.5`), each loaded
    with --dump-dom (the page's data attributes: ready, errors, where each
    body's centre is drawn) and with --screenshot;
  * no console message at all (Chromium logs them to stderr as CONSOLE
    lines; the page writes none, so any is an error or a CSP refusal);
  * no network request made for the page (Chromium's own net log; the
    browser's own background requests, whose initiator is "not an origin",
    are told apart; a probe page that does make one shows that the check can fail);
  * the mechanism moved: the body centres differ and the scene's pixels
    differ between the two positions;
  * the frame at t = 0 shows every body: each body's colour is drawn at
    its centre.
"""

import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--force-device-scale-factor=1",
    "--window-size=1000,1400",
    "--virtual-time-budget=3000",
    "--enable-logging=stderr",
    "--v=0",
]

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def chromium(url, *extra):
    """Runs Chromium on `url` with a fresh profile; returns (stdout, stderr, net log events)."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    with tempfile.TemporaryDirectory() as tmp:
        netlog = os.path.join(tmp, "net.json")
        args = [browser, *FLAGS, "--user-data-dir=" + os.path.join(tmp, "profile"), "--log-net-log=" + netlog, *extra, url]
        run = subprocess.run(args, capture_output=True, text=True, timeout=120)
        if run.returncode != 0:
            sys.exit(f"chromium failed ({run.returncode}): {run.stderr[-2000:]}")
        with open(netlog) as f:
            text = f.read()
        # A log cut short (the browser exits before closing it) lacks its ending.
        if not text.rstrip().endswith("}"):
            text = text.rstrip().rstrip(",") + "]}"
        log = json.loads(text)
    return run.stdout, run.stderr, log


def console_lines(stderr):
    return [line for line in stderr.splitlines() if ":CONSOLE" in line]


def page_requests(log):
    """URLs the network stack was asked for on behalf of a page (not by the browser itself)."""
    types = {v: k for k, v in log["constants"]["logEventTypes"].items()}
    urls = []
    for e in log.get("events", []):
        p = e.get("params") or {}
        if types.get(e["type"]) == "URL_REQUEST_START_JOB" and "url" in p:
            if p.get("initiator") != "not an origin" or "file://" in p.get("network_isolation_key", ""):
                urls.append(p["url"])
    return urls


def body_attributes(dom):
    m = re.search(r"<body([^>]*)>", dom)
    attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', m.group(1))) if m else {}
    unescape = lambda s: s.replace("&quot;", '"').replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
    return {k: unescape(v) for k, v in attrs.items()}


def read_png(path):
    """(width, height, rows of (r, g, b)) of an 8-bit RGB or RGBA, non-interlaced PNG."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and colour in (2, 6) and interlace == 0, "unsupported PNG"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    bpp = 4 if colour == 6 else 3
    raw, stride, rows, prev = zlib.decompress(idat), width * bpp, [], bytearray(width * bpp)
    for y in range(height):
        ftype, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * bpp : x * bpp + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def near(rgb, hex_colour, tol=40):
    want = tuple(int(hex_colour[i : i + 2], 16) for i in (1, 3, 5))
    return all(abs(a - b) <= tol for a, b in zip(rgb, want))


def load(report, pos, tmp):
    url = "file://" + os.path.abspath(report) + f"#pos={pos}"
    dom, err, log = chromium(url, "--dump-dom")
    shot = os.path.join(tmp, f"shot{len(os.listdir(tmp))}.png")
    _, err2, log2 = chromium(url, "--screenshot=" + shot)
    return body_attributes(dom), console_lines(err) + console_lines(err2), page_requests(log) + page_requests(log2), shot


def scene_changes(attrs, shot0, shot1):
    """How many pixels of the scene (where `attrs` says it is) differ between two screenshots."""
    w, h, px0 = read_png(shot0)
    _, _, px1 = read_png(shot1)
    scene = json.loads(attrs.get("data-scene", "{}"))
    x0, y0 = int(scene.get("x", 0)), int(scene.get("y", 0))
    x1, y1 = min(w, x0 + int(scene.get("width", 0))), min(h, y0 + int(scene.get("height", 0)))
    return sum(px0[y][x] != px1[y][x] for y in range(y0, y1) for x in range(x0, x1))


def animation(report, tmp, what=""):
    """The checks of a page with an animation, at two slider positions; returns the loads."""
    loads = {pos: load(report, pos, tmp) for pos in (0, 0.5)}
    for pos, (attrs, console, requests, _) in loads.items():
        check(attrs.get("data-ready") == "1", f"{what}pos={pos}: the page ran to its end")
        check("data-errors" not in attrs, f"{what}pos={pos}: no script error {attrs.get('data-errors', '')}")
        check(not console, f"{what}pos={pos}: no console message {console}")
        check(not requests, f"{what}pos={pos}: no network request {requests}")
    (a0, _, _, shot0), (a1, _, _, shot1) = loads[0], loads[0.5]
    bodies0, bodies1 = json.loads(a0.get("data-bodies", "[]")), json.loads(a1.get("data-bodies", "[]"))
    check(len(bodies0) > 0 and len(bodies0) == len(bodies1), f"{what}{len(bodies0)} bodies drawn")
    moved = max((abs(p["x"] - q["x"]) + abs(p["y"] - q["y"]) for p, q in zip(bodies0, bodies1)), default=0)
    check(moved > 5, f"{what}a body centre moved {moved:.1f} px between pos=0 and pos=0.5")
    changed = scene_changes(a0, shot0, shot1)
    check(changed > 500, f"{what}{changed} pixels of the scene differ between pos=0 and pos=0.5")
    w, h, px0 = read_png(shot0)
    for b in bodies0:
        cx, cy = round(b["x"]), round(b["y"])
        hits = sum(
            near(px0[y][x], b["colour"]) for y in range(cy - 3, cy + 4) for x in range(cx - 3, cx + 4) if 0 <= x < w and 0 <= y < h
        )
        check(hits >= 20, f"{what}t = 0: body {b['name']} drawn in {b['colour']} at ({cx}, {cy}) ({hits} of 49 pixels)")
    return loads


def main():
    args = sys.argv[1:]
    if not args or not os.path.isfile(args[0]):
        sys.exit(__doc__)
    report = args[0]
    screenshot_out = args[args.index("--screenshot") + 1] if "--screenshot" in args else None
    also = [args[i + 1] for i, a in enumerate(args) if a == "--also"]
    spatial = [args[i + 1] for i, a in enumerate(args) if a == "--spatial"]
    screenshot_3d = args[args.index("--screenshot-3d") + 1] if "--screenshot-3d" in args else None

    with tempfile.TemporaryDirectory() as tmp:
        # The checks can fail: a page that logs an error and fetches an image is caught.
        probe = os.path.join(tmp, "probe.html")
        with open(probe, "w") as f:
            f.write('<html><body><img src="http://127.0.0.1:9/probe.png"><script>console.error("probe")</script></body></html>')
        _, err, log = chromium("file://" + probe, "--dump-dom")
        check(len(console_lines(err)) >= 1, "probe: a console message is seen")
        check(any("127.0.0.1:9/probe.png" in u for u in page_requests(log)), "probe: a page's network request is seen")

        loads = animation(report, tmp)
        for page in also:
            path, _, fragment = page.partition("#")
            dom, err, log = chromium("file://" + os.path.abspath(path) + "#" + fragment, "--dump-dom")
            attrs, console, requests = body_attributes(dom), console_lines(err), page_requests(log)
            check(attrs.get("data-ready") == "1" and "data-errors" not in attrs, f"{page}: the page ran to its end without error {attrs.get('data-errors', '')}")
            check(not console and not requests, f"{page}: no console message {console}, no network request {requests}")
        for page in spatial:
            spatial_loads = animation(page, tmp, "3-D ")
            # Orbiting changes the view: the same instant from elsewhere.
            turned = load(page, "0.5&yaw=60&pitch=20&zoom=1.5", tmp)
            (a0, _, _, shot0), (a1, console, requests, shot1) = spatial_loads[0.5], turned
            check(not console and not requests and "data-errors" not in a1, f"3-D turned: no console message {console}, request {requests} or error")
            view0, view1 = json.loads(a0.get("data-view", "{}")), json.loads(a1.get("data-view", "{}"))
            check(abs(view1.get("yaw", 0) - math.radians(60)) < 1e-9 and view0.get("yaw") != view1.get("yaw"), f"3-D: the view turned from {view0} to {view1}")
            changed = scene_changes(a0, shot0, shot1)
            check(changed > 2000, f"3-D: {changed} pixels of the scene differ between two views of t = pos 0.5")
            # Playing advances the frames. It runs on a manual clock
            # (`#clock=N`: N frames 1/60 s apart): Chromium's own animation
            # frames in headless mode are not to be relied on; on a loaded
            # machine 10 s of virtual time gave none at all.
            frames, speed = 90, 0.5
            dom, _, _ = chromium("file://" + os.path.abspath(page) + f"#speed={speed}&clock={frames}", "--dump-dom")
            attrs = body_attributes(dom)
            moves, shown = int(attrs.get("data-moves", "0")), float(attrs.get("data-time", "nan"))
            played = frames / 60 * speed
            check(moves > 0, f"3-D: playing, the animation moved to another frame {moves} times")
            check(abs(shown - played) < 1e-9, f"3-D: playing {frames} frames at {speed}x shows t = {shown} (expected {played})")

        if screenshot_out:
            url = "file://" + os.path.abspath(report) + "#pos=0.3&trace"
            chromium(url, "--screenshot=" + os.path.abspath(screenshot_out), "--window-size=1000,1000")
            check(os.path.isfile(screenshot_out), "wrote " + screenshot_out)
        if screenshot_3d and spatial:
            url = "file://" + os.path.abspath(spatial[0]) + "#pos=0.3&yaw=-70&pitch=25&zoom=1.6"
            chromium(url, "--screenshot=" + os.path.abspath(screenshot_3d), "--window-size=1000,760")
            check(os.path.isfile(screenshot_3d), "wrote " + screenshot_3d)

    if failures:
        sys.exit(f"{len(failures)} check(s) failed")
    print("all viewer checks passed")


if __name__ == "__main__":
    main()
