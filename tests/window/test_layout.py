#!/usr/bin/env python3
"""The debug view's layout at the sizes people run it: a 720-px-tall window (--size
720x720, 1100x720 with the panels), 1280x800 (--size 900x800) and a 16:9 picture in a
1280x800 window (--window). Nothing in the
sidebar is cut off, the inspector windows (texture, pixel trace) sit beside the image
and not over it, the image keeps its aspect, F1 gives it the whole window at that
aspect, and the floating windows' places persist (ImGui's ini in $XDG_CONFIG_HOME).

usage: test_layout.py KILN OUT_DIR   (under xvfb-run with a screen of at least 1280x800)
"""
import json
import os
import shutil
import subprocess
import sys
import time

KILN, OUT = sys.argv[1:3]
SIDEBAR = 380
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def inside(rect, box):
    return rect[0] >= box[0] - 0.5 and rect[1] >= box[1] - 0.5 and rect[2] <= box[2] + 0.5 and rect[3] <= box[3] + 0.5


def overlaps(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


class Window:
    def __init__(self, size, name, fresh=True, window=None):
        self.dir = os.path.join(OUT, name)
        shutil.rmtree(self.dir, ignore_errors=True)
        os.makedirs(self.dir)
        self.probe_file = os.path.join(self.dir, "probe.json")
        self.config = os.path.join(OUT, "config-" + name)
        if fresh:  # the first-run layout, whatever an earlier run left
            shutil.rmtree(self.config, ignore_errors=True)
        self.kiln = subprocess.Popen([KILN, "--paused", "--size", size, "--budget", "0", "--view", "gbuffer.normal",
                                      "--ui-probe", self.probe_file] + (["--window", window] if window else []),
                                     env=dict(os.environ, XDG_CONFIG_HOME=self.config), cwd=self.dir,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.wait_for(lambda p: p["frame"] >= 3, "the first frames")
        self.id = subprocess.run(["xdotool", "search", "--sync", "--name", "^Kiln$"], check=True,
                                 capture_output=True, text=True).stdout.split()[0]

    def probe(self):
        deadline = time.time() + 120  # a deadline: the first frames compile every shader
        while time.time() < deadline:
            if self.kiln.poll() is not None:
                raise RuntimeError("kiln exited:\n" + self.kiln.stdout.read()[-2000:])
            try:
                with open(self.probe_file) as f:
                    return json.load(f)
            except (OSError, ValueError):
                time.sleep(0.1)
        raise RuntimeError("no probe file")

    def wait_for(self, predicate, what, timeout=120):
        deadline = time.time() + timeout
        while time.time() < deadline:
            p = self.probe()
            if predicate(p):
                return p
            time.sleep(0.2)
        raise RuntimeError("timed out waiting for " + what)

    def frames_later(self, n=3):
        start = self.probe()["frame"]
        return self.wait_for(lambda p: p["frame"] >= start + n, "%d frames" % n)

    def xdotool(self, *args):
        subprocess.run(["xdotool"] + list(args), check=True)

    def screenshot(self, name):
        subprocess.run(["import", "-window", self.id, os.path.join(self.dir, name)], check=True)

    def close(self):
        self.kiln.terminate()
        try:
            self.kiln.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.kiln.kill()


def check_size(size, window_w, window_h, window=None):
    name = "%dx%d" % (window_w, window_h) + ("-window" if window else "")
    image_w, image_h = (int(v) for v in size.split("x"))
    w = Window(size, name, window=window)
    try:
        p = w.frames_later()
        widgets = p["widgets"]
        sidebar = [0, 0, SIDEBAR, window_h]
        rows = [k for k in widgets if k.split(":")[0] in ("pipeline-switcher", "show-graph", "show-compare", "frame-line",
                                                           "save-image", "pass-enabled", "pass", "tab")]
        cut = [k for k in rows if not inside(widgets[k], sidebar)]
        check(len(rows) >= 20 and not cut, "%s: all %d sidebar widgets inside the sidebar (cut: %s)" % (name, len(rows), cut))
        check(all(k in widgets for k in ("show-compare", "frame-line", "tab:Scene")),
              "%s: the compare button, the frame-time line and every tab are shown" % name)
        ix, iy, iw, ih = p["image"]
        image = [ix, iy, ix + iw, iy + ih]
        check(abs(iw / ih - image_w / image_h) < 0.01, "%s: the image keeps its %s aspect: %dx%d" % (name, size, iw, ih))
        canvas = widgets.get("texture-canvas")
        check(canvas is not None and not overlaps(canvas, image),
              "%s: the texture window is beside the image, not over it: %s vs %s" % (name, canvas, image))
        w.screenshot("texture.png")

        # "save image": the image's texture as it holds it, at the render size.
        x0, y0, x1, y1 = widgets["save-image"]
        w.xdotool("mousemove", "--window", w.id, str(int((x0 + x1) / 2)), str(int((y0 + y1) / 2)))
        time.sleep(0.2)
        w.xdotool("click", "1")
        p = w.wait_for(lambda p: ".png" in p.get("saved", ""), "the saved image")
        saved = os.path.join(w.dir, p["saved"].split(" ")[0])  # relative to kiln's working directory
        size = subprocess.run(["identify", "-format", "%wx%h", saved], capture_output=True, text=True).stdout
        check(os.path.basename(saved) == "gbuffer.normal.png" and size == "%dx%d" % (p["image"][2], p["image"][3]),
              "%s: save image wrote what the image shows at its size: %s %s" % (name, saved, size))

        # A right click on the image: the trace window joins the column, below the texture window.
        w.xdotool("mousemove", "--window", w.id, str(ix + iw // 2), str(iy + ih * 3 // 4))
        time.sleep(0.2)
        w.xdotool("click", "3")
        p = w.wait_for(lambda p: "trace-window" in p["widgets"], "the trace window")
        p = w.frames_later()
        ix, iy, iw, ih = p["image"]
        image = [ix, iy, ix + iw, iy + ih]
        trace, canvas = p["widgets"]["trace-window"], p["widgets"].get("texture-canvas")
        check(not overlaps(trace, image) and canvas is not None and not overlaps(canvas, image) and
              not overlaps(trace, canvas), "%s: trace and texture windows share the column: %s %s, image %s"
              % (name, trace, canvas, image))
        w.screenshot("trace.png")

        # F1: no panels; the image takes the whole window at its aspect.
        w.xdotool("key", "--window", w.id, "F1")
        p = w.wait_for(lambda p: p["image"][0] < SIDEBAR, "F1")
        fit = min(window_w / image_w, window_h / image_h)
        want = [round((window_w - image_w * fit) / 2), round((window_h - image_h * fit) / 2),
                round(image_w * fit), round(image_h * fit)]
        check(all(abs(a - b) <= 1 for a, b in zip(p["image"], want)),
              "%s: F1 fits the image to the whole window: %s, want %s" % (name, p["image"], want))
        w.screenshot("f1.png")
        w.xdotool("key", "--window", w.id, "F1")
        p = w.wait_for(lambda p: p["image"][0] >= SIDEBAR, "the panels back")

        # A click held on the docked window's title bar (ImGui starts a move there) that
        # moves nothing: it stays docked, and the image keeps its place.
        x0, y0, x1, y1 = p["widgets"]["texture-window"]
        w.xdotool("mousemove", "--window", w.id, str(int(x0 + 120)), str(int(y0 + 8)), "mousedown", "1")
        w.frames_later()  # held still over several frames, as a person's click is
        w.xdotool("mouseup", "1")
        q = w.frames_later()
        check(q["widgets"]["texture-window"] == p["widgets"]["texture-window"] and q["image"] == p["image"],
              "%s: a click inside the docked texture window leaves it docked: %s" % (name, q["widgets"]["texture-window"]))

        # Drag the texture window out of the column by its title bar: it floats where it is
        # put, over the image if the user wants it there, and stays there in the next run.
        x0, y0, x1, y1 = p["widgets"]["texture-window"]
        w.xdotool("mousemove", "--window", w.id, str(int(x0 + 60)), str(int(y0 + 8)), "mousedown", "1")
        for step in range(1, 6):
            w.xdotool("mousemove", "--window", w.id, str(int(x0 + 60 - step * 60)), str(int(y0 + 8 + step * 20)))
            w.frames_later(1)
        w.xdotool("mouseup", "1")
        p = w.frames_later()
        moved = p["widgets"]["texture-window"]
        check(abs(moved[0] - (x0 - 300)) <= 3 and abs(moved[1] - (y0 + 100)) <= 3,
              "%s: the texture window follows a drag out of the column: %s -> %s" % (name, [x0, y0], moved[:2]))
    finally:
        w.close()
    ini = os.path.join(w.config, "kiln", "imgui.ini")
    check(os.path.exists(ini) and "[Window][Texture]" in open(ini).read() and "[Kiln][Floating]\nTexture" in open(ini).read(),
          "%s: window places, and that the texture window floats, are kept in %s" % (name, ini))
    again = Window(size, name, fresh=False, window=window)
    try:
        p = again.frames_later()
        kept = p["widgets"].get("texture-window")
        check(kept is not None and all(abs(a - b) <= 2 for a, b in zip(kept, moved)),
              "%s: the next run opens the texture window where it was left: %s (left at %s)" % (name, kept, moved))
    finally:
        again.close()


try:
    check_size("720x720", 720 + SIDEBAR, 720)
    check_size("900x800", 900 + SIDEBAR, 800)
    # --window sets the window apart from --size: a 16:9 picture in a 1280x800 window.
    check_size("640x360", 1280, 800, window="1280x800")
except RuntimeError as e:
    check(False, str(e))
print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
