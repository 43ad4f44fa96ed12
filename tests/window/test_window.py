#!/usr/bin/env python3
"""The window as a user drives it: kiln under a virtual X server, clicked and typed at
with xdotool, judged on what the screen shows (screenshots read back with ImageMagick)
and on what a headless run of the same frame reads back. kiln --ui-probe says where each
widget is; nothing else of the window's insides is used.

usage: test_window.py KILN SOURCE_DIR OUT_DIR BUGGY_MODULE FIXED_MODULE
       (run under xvfb-run; ctest does). The two modules are builds of
       tests/core/modules/faulty.cpp: the window must survive the first and pick up the
       second.
"""
import difflib
import json
import os
import shutil
import subprocess
import sys
import time

KILN, SOURCE, OUT, BUGGY_MODULE, FIXED_MODULE = sys.argv[1:6]
W, H = 320, 640  # the image; the window adds the panels' column
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def sh(*args):
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout


def probe(timeout=60):
    # A deadline, not a count of tries: on a loaded machine the window's first frames
    # (shader compiles on llvmpipe) took longer than the 5 s this once allowed.
    deadline = time.time() + timeout
    while time.time() < deadline:
        if kiln.poll() is not None:
            raise RuntimeError("kiln exited before writing its probe file")
        try:
            with open(PROBE) as f:
                return json.load(f)
        except (OSError, ValueError):
            time.sleep(0.1)
    raise RuntimeError("no probe file after %d s" % timeout)


def wait_for(predicate, what, timeout=60):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if kiln.poll() is not None:
            raise RuntimeError("kiln exited while waiting for " + what)
        p = probe()
        if predicate(p):
            return p
        time.sleep(0.2)
    raise RuntimeError("timed out waiting for " + what + "; probe: " + json.dumps({k: v for k, v in probe().items() if k != "widgets"})[:2000])


def frames_later(n=3):
    """Waits until the window has drawn n more frames (what was clicked has landed)."""
    start = probe()["frame"]
    wait_for(lambda p: p["frame"] >= start + n, "%d frames" % n)


def centre(widget):
    x0, y0, x1, y1 = probe()["widgets"][widget]
    return int((x0 + x1) / 2), int((y0 + y1) / 2)


def click(widget, ctrl=False):
    x, y = centre(widget)
    sh("xdotool", "mousemove", "--window", WINDOW, str(x), str(y))
    time.sleep(0.2)
    if ctrl:
        sh("xdotool", "keydown", "ctrl", "click", "1", "keyup", "ctrl")
    else:
        sh("xdotool", "click", "1")
    frames_later()


def screen_pixel(x, y, shot):
    """The screenshot's RGB (0..255) at window pixel (x, y)."""
    text = sh("convert", shot, "-crop", "1x1+%d+%d" % (x, y), "-depth", "8", "txt:-")
    rgb = text.splitlines()[1].split("(")[1].split(")")[0].split(",")
    return [float(c) for c in rgb[:3]]


def screenshot(name):
    path = os.path.join(OUT, name)
    sh("import", "-window", WINDOW, path)
    return path


def image_mean(shot, p, size=9):
    """Mean RGB of a size×size patch near the bottom of the image (the floor), where
    the texture window, open at the top right, does not cover it."""
    ix, iy, iw, ih = p["image"]
    cx, cy = ix + iw * 3 // 4, iy + ih - 24
    text = sh("convert", shot, "-crop", "%dx%d+%d+%d" % (size, size, cx - size // 2, cy - size // 2),
              "-resize", "1x1!", "-depth", "16", "txt:-")
    rgb = text.splitlines()[1].split("(")[1].split(")")[0].split(",")
    return sum(float(c) for c in rgb[:3]) / 3


os.makedirs(OUT, exist_ok=True)
PROBE = os.path.join(OUT, "probe.json")
pipelines = os.path.join(OUT, "pipelines")
shutil.rmtree(pipelines, ignore_errors=True)
shutil.copytree(os.path.join(SOURCE, "pipelines"), pipelines)
default = os.path.join(pipelines, "default.json")
original_text = open(default).read()
if os.path.exists(PROBE):
    os.remove(PROBE)
# A module whose execute() segfaults (KILN_TEST_FAULT), in a module directory of its own
# ahead of the build's (the pipeline that uses it is written at step 8).
modules = os.path.join(OUT, "modules")
shutil.rmtree(modules, ignore_errors=True)
os.makedirs(modules)
shutil.copy(BUGGY_MODULE, os.path.join(modules, "libpass_test_faulty.so"))
build_modules = os.path.join(os.path.dirname(os.path.dirname(KILN)), "modules")

# Panel positions persist in $XDG_CONFIG_HOME/kiln/imgui.ini: a fresh one, so the layout
# is the first-run layout whatever an earlier run left.
config = os.path.join(OUT, "config")
shutil.rmtree(config, ignore_errors=True)

# What a headless run reads back for the same paused frame at the same size.
dump = os.path.join(OUT, "dump")
shutil.rmtree(dump, ignore_errors=True)
sh(KILN, "--headless", "--paused", "--size", "%dx%d" % (W, H), "--pipeline", default, "--dump", dump,
   "--view", "gbuffer.albedo", "--no-live")

saves = os.path.join(OUT, "saves")
shutil.rmtree(saves, ignore_errors=True)
kiln = subprocess.Popen([KILN, "--paused", "--size", "%dx%d" % (W, H), "--pipeline", default, "--budget", "0",
                         "--dump", saves,
                         "--ui-probe", PROBE, "--modules", modules + ":" + build_modules],
                        env=dict(os.environ, KILN_TEST_FAULT="segv@execute", XDG_CONFIG_HOME=config),
                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
try:
    wait_for(lambda p: p["frame"] >= 3, "the first frames")
    WINDOW = sh("xdotool", "search", "--sync", "--name", "^Kiln$").split()[0]
    p = probe()
    check(p["image"][2] == W and p["image"][3] == H, "the image is %dx%d beside the panels: %s" % (W, H, p["image"]))

    # 1. Select a texture: the texture window opens on it; the value under a known
    #    texel is what the headless read-back has there.
    click("tab:Textures")
    click("texture:gbuffer.albedo")
    p = wait_for(lambda p: p["viewed"] == "gbuffer.albedo" and "texture-canvas" in p["widgets"], "the texture window")
    x0, y0, x1, y1 = p["widgets"]["texture-canvas"]
    seen = set()
    cw, ch = x1 - x0, y1 - y0
    zoom = min(cw / W, ch / H)  # the canvas fits the whole texture, centred
    for want in ((W // 2, H // 2), (6, H * 6 // 10), (W // 2, H // 12)):  # back wall, left wall, floor
        sx = x0 + cw / 2 + (want[0] + 0.5 - W / 2) * zoom
        sy = y1 - (ch / 2 + (want[1] + 0.5 - H / 2) * zoom)
        sh("xdotool", "mousemove", "--window", WINDOW, str(int(sx)), str(int(sy)))
        p = wait_for(lambda p: "readout" in p and all(abs(a - b) <= 2 for a, b in zip(p["readout"]["texel"], want)),
                     "a readout near texel %s" % (want,))
        tx, ty, _ = p["readout"]["texel"]
        value = p["readout"]["value"]
        seen.add(tuple(round(v, 3) for v in value[:3]))
        # The dump's PNG is top row first; GL's row 0 is the bottom. RGBA8 is exact in PNG.
        text = sh("convert", os.path.join(dump, "gbuffer.albedo.png"), "-crop", "1x1+%d+%d" % (tx, H - 1 - ty),
                  "-depth", "8", "txt:-")
        expected = [float(c) / 255 for c in text.splitlines()[1].split("(")[1].split(")")[0].split(",")[:3]]
        check(all(abs(a - b) <= 0.5 / 255 for a, b in zip(value[:3], expected)),
              "readout at texel (%d, %d) %s equals the headless read-back %s (within half a step of 8 bits)"
              % (tx, ty, [round(v, 4) for v in value[:3]], [round(v, 4) for v in expected]))
    check(len(seen) == 3, "three places, three different albedos: %s" % seen)
    #    "save" writes what the window shows: the same pixels as the headless dump.
    click("texture-save")
    p = wait_for(lambda p: "saved" in p, "the texture saved")
    saved = os.path.join(saves, "gbuffer.albedo.png")
    check(p["saved"] == saved[:-len(".png")] + ".png", "saved to %s: %s" % (saved, p["saved"]))
    differing = subprocess.run(["compare", "-metric", "AE", saved, os.path.join(dump, "gbuffer.albedo.png"), "null:"],
                               capture_output=True, text=True).stderr.strip()
    check(differing == "0", "the saved gbuffer.albedo equals the headless dump's, pixel for pixel (%s differ)" % differing)

    # 2. An integer texture (R32UI voxel sums and counts) is not black: the fitted range is > 0.
    click("texture-filter")
    sh("xdotool", "type", "--window", WINDOW, "sums")
    # The whole word first: the characters reach ImGui one a frame, and the rows move as
    # the filter narrows (a click aimed after "s" landed on another row after "sums").
    wait_for(lambda p: p["texture_filter"] == "sums" and "texture:voxelize.sums" in p["widgets"],
             "voxelize.sums in the list filtered by \"sums\"")
    click("texture:voxelize.sums")
    p = wait_for(lambda p: p["viewed"] == "voxelize.sums" and "fit" in p, "a fit of voxelize.sums")
    check(p["fit"][1] >= 1, "voxelize.sums (R32UI) fits to a range with counts: %s" % p["fit"])
    # ... and its 64-bin histogram is drawn under the image: as wide as the window, with
    # bars (ImGui's plot colour, orange) in it. It was 1 px wide and empty.
    p = wait_for(lambda p: "texture-histogram" in p["widgets"], "the histogram")
    hx0, hy0, hx1, hy1 = [int(v) for v in p["widgets"]["texture-histogram"]]
    check(hx1 - hx0 > 100, "the histogram is %d px wide" % (hx1 - hx0))
    text = sh("convert", screenshot("histogram.png"), "-crop", "%dx%d+%d+%d" % (hx1 - hx0, hy1 - hy0, hx0, hy0),
              "-depth", "8", "txt:-")
    bars = 0
    for line in text.splitlines()[1:]:
        r, g, b = [float(c) for c in line.split("(")[1].split(")")[0].split(",")[:3]]
        bars += r > 150 and g > 90 and b < 80
    check(bars > 20, "the histogram shows bars: %d orange pixels" % bars)
    # ... and a legend of the false-colour map along the canvas's bottom: turbo's green in
    # the middle, its dark red at the high end. (Its low end sits under the sidebar's
    # column at this window size.)
    cx0, cy0, cx1, cy1 = [int(v) for v in p["widgets"]["texture-canvas"]]
    middle = screen_pixel((cx0 + cx1) // 2, cy1 - 4, os.path.join(OUT, "histogram.png"))
    high = screen_pixel(cx1 - 4, cy1 - 4, os.path.join(OUT, "histogram.png"))
    check(middle[1] > 150 and middle[1] > middle[0] and middle[1] > middle[2], "the legend is green midway: %s" % middle)
    check(high[0] > 100 and high[0] > 3 * high[2], "the legend ends red: %s" % high)
    # The sidebar, clicked since, lies over the legend's low end and hides it: it draws
    # its background whenever another window overlaps its column (only then: elsewhere
    # the window's clear stands in for it). Transparent, the legend's blue shows through.
    ix = p["image"][0]
    check(cx0 < ix - 40, "the texture window reaches under the sidebar's column: %d < %d" % (cx0, ix))
    under = screen_pixel((cx0 + ix) // 2, cy1 - 4, os.path.join(OUT, "histogram.png"))
    check(max(under) < 40, "the sidebar hides the legend under it: %s" % under)

    # 3. A parameter: ctrl+click composite.exposure, type 0.25; the image darkens.
    before = image_mean(screenshot("before.png"), probe())
    click("pass:composite")
    wait_for(lambda p: "param:composite.exposure" in p["widgets"], "composite's parameters")
    click("param:composite.exposure", ctrl=True)
    sh("xdotool", "key", "--window", WINDOW, "ctrl+a")
    sh("xdotool", "type", "--window", WINDOW, "0.25")
    sh("xdotool", "key", "--window", WINDOW, "Return")
    p = wait_for(lambda p: p["passes"]["composite"]["params"]["exposure"] == "0.25", "exposure 0.25")
    frames_later()
    after = image_mean(screenshot("after.png"), probe())
    check(after < before * 0.75, "exposure 1 -> 0.25 darkens the floor: mean %.0f -> %.0f (of 65535)" % (before, after))

    # 4. Toggle a pass off.
    click("pass-enabled:bloom")
    p = wait_for(lambda p: p["passes"]["bloom"]["state"] == "disabled", "bloom disabled")
    others = [k for k, v in p["passes"].items() if k != "bloom" and v["state"] == "disabled"]
    check(not others, "bloom's checkbox disables bloom and nothing else (also disabled: %s)" % others)

    # 5. Write back: only the edited values change in the file.
    click("write-back")
    frames_later()
    written = open(default).read()
    expected_text = original_text.replace('"exposure": 1.0', '"exposure": 0.25', 1)
    check(written != original_text and "\"exposure\": 0.25" in written, "write-back wrote the new exposure")
    diff = [l for l in difflib.ndiff(original_text.splitlines(), written.splitlines()) if l[:1] in "+-"]
    removed = [l for l in diff if l.startswith("-")]
    added = [l for l in diff if l.startswith("+")]
    check(len(removed) == 1 and "exposure" in removed[0] and len(added) == 2 and
          any("\"exposure\": 0.25" in l for l in added) and any("\"enabled\": false" in l for l in added),
          "write-back changed only the edited values (the exposure line, and enabled: false added to bloom): %s" % diff)

    # 6. The graph view.
    click("show-graph")
    p = wait_for(lambda p: "graph-node:gbuffer" in p["widgets"], "the graph view")
    missing = [k for k in p["passes"] if "graph-node:" + k not in p["widgets"]]
    check(not missing, "the graph view shows a node per pass (missing: %s)" % missing)
    screenshot("graph.png")
    click("show-graph")  # and the same button closes it
    p = wait_for(lambda p: not any(w.startswith("graph-node:") for w in p["widgets"]), "the graph view closed")

    # 7. Switch pipeline to voxels.json without a restart.
    click("pipeline-switcher")
    wait_for(lambda p: "pipeline:voxels.json" in p["widgets"], "the pipeline list")
    click("pipeline:voxels.json")
    p = wait_for(lambda p: p["pipeline"].endswith("voxels.json"), "voxels.json running")
    check(not p["errors"] and not p["editor_error"], "voxels.json runs without errors: %s %s" % (p["errors"], p["editor_error"]))
    screenshot("voxels.png")

    # 8. A pass module that segfaults in execute(): the window names it and keeps
    #    drawing; a fixed build written over it is picked up live.
    #    (Written now, and named to sort near the top: the list at 640 px shows ten.)
    with open(os.path.join(pipelines, "crash.json"), "w") as f:
        f.write('{"output": "bad.color", "passes": [{"id": "bad", "module": "test_faulty"}]}\n')
    click("pipeline-switcher")
    wait_for(lambda p: "pipeline:crash.json" in p["widgets"], "the pipeline list")
    click("pipeline:crash.json")
    p = wait_for(lambda p: p["pipeline"].endswith("crash.json") and p["errors"], "the fault named")
    named = [e for e in p["errors"] if 'pass "bad" (libpass_test_faulty.so): SIGSEGV' in e and "in execute()" in e]
    check(len(named) == 1 and len(p["errors"]) == 1, "the segfault is one error naming the pass and the module: %s" % p["errors"])
    frames_later(5)
    check(kiln.poll() is None, "the window keeps drawing after the segfault")
    screenshot("fault.png")
    shutil.copy(FIXED_MODULE, os.path.join(modules, ".libpass_test_faulty.so.new"))
    os.rename(os.path.join(modules, ".libpass_test_faulty.so.new"), os.path.join(modules, "libpass_test_faulty.so"))
    p = wait_for(lambda p: not p["errors"], "the fixed build picked up")
    frames_later()
    shot = screenshot("fixed.png")
    ix, iy, iw, ih = p["image"]
    r, g, b = screen_pixel(ix + iw // 2, iy + ih - 24, shot)  # below the texture window
    check(g > 200 and b < 40, "the fixed build fills the image with its green: %s" % [r, g, b])

    # 9. The compare view: compare.json turns it on with figures of composite.hdr
    #    against the reference; the line follows a drag.
    click("pipeline-switcher")
    wait_for(lambda p: "pipeline:compare.json" in p["widgets"], "the pipeline list")
    click("pipeline:compare.json")
    p = wait_for(lambda p: p["pipeline"].endswith("compare.json") and "errors" in p["compare"] and
                 p["compare"]["errors"]["reference_paths"] >= 8, "compare figures", 300)
    e = p["compare"]["errors"]
    check(p["compare"]["on"] and 0 < e["rmse"] < 10 and 0 < e["ssim"] <= 1 and e["reference_paths"] >= 8,
          "compare.json shows RMSE %.4g, SSIM %.4f against a reference of %d paths" % (e["rmse"], e["ssim"], e["reference_paths"]))
    # Input at a slow frame rate (compare.json renders the reference: over a second a
    # frame here): Ctrl+A and a word typed within one frame all arrive, in order. ImGui
    # 1.86 polled key states per frame, so the Ctrl+A was lost and the word appended.
    check(p["compare"]["on"] and "compare-tonemap" in p["widgets"], "turning the compare view on brings its tab forward")
    click("tab:Textures")
    click("texture-filter")
    sh("xdotool", "key", "--window", WINDOW, "ctrl+a")
    sh("xdotool", "type", "--window", WINDOW, "--delay", "1", "albedo")
    p = wait_for(lambda p: "texture:gbuffer.albedo" in p["widgets"] and "texture:voxelize.sums" not in p["widgets"],
                 "the filter replaced by \"albedo\"", 120)
    check("texture:gbuffer.albedo" in p["widgets"], "Ctrl+A and \"albedo\" typed in one slow frame (%.0f ms) replace the filter"
          % p["frame_ms"])
    ix, iy, iw, ih = p["image"]
    x, _ = centre("compare-line")
    y = iy + ih - 16  # below the texture window, which is open at the top right
    sh("xdotool", "mousemove", "--window", WINDOW, str(x), str(y), "mousedown", "1")
    for step in range(1, 6):
        sh("xdotool", "mousemove", "--window", WINDOW, str(int(x - step * (x - (ix + iw // 4)) / 5)), str(y))
        # Two frames: the one in progress may have polled its input before the move (one
        # was not enough under CI's load: the mouseup then ended the drag a step short).
        frames_later(2)
    sh("xdotool", "mouseup", "1")
    wait_for(lambda p: abs(p["compare"]["split"] - 0.25) < 0.03, "the line at a quarter")
    frames_later()
    p = probe()
    check(abs(p["compare"]["split"] - 0.25) < 0.03,
          "dragging the compare line to a quarter leaves it there after the button is up: %.3f" % p["compare"]["split"])
    error_split = float(p["passes"]["error"]["params"]["split"])
    check(abs(error_split - p["compare"]["split"]) < 1e-6,
          "one split: the error pass's split follows the line (%.3f)" % error_split)
    screenshot("compare.png")

    # 10. Back to default.json: the compare view follows the pipeline and goes off (it
    #     stayed on, comparing textures the default graph does not have).
    click("pipeline-switcher")
    wait_for(lambda p: "pipeline:default.json" in p["widgets"], "the pipeline list")
    click("pipeline:default.json")
    wait_for(lambda p: p["pipeline"].endswith("default.json"), "default.json loaded")
    frames_later()
    p = probe()
    check(not p["compare"]["on"], "leaving compare.json turns the compare view off")
    check(not any("reference" in e for e in p["errors"]), "no error about the reference's textures: %s" % p["errors"])

    # 11. A pixel traced through the graph: a right click on the image lists every
    #     texture's value there; the output's row is the pixel the screen shows.
    ix, iy, iw, ih = p["image"]
    x, y = ix + iw // 3, iy + ih - 24  # the floor, clear of the texture window (top right)
    # A still frame: the voxels' fed-back bounces converge over frames after the
    # pipeline switch above (slow ones on a busy machine), so the screen would move on.
    wait_for(lambda p: not p.get("settling", True), "the frame to settle", timeout=180)
    on_screen = screen_pixel(x, y, screenshot("before-trace.png"))
    sh("xdotool", "mousemove", "--window", WINDOW, str(x), str(y))
    time.sleep(0.2)
    sh("xdotool", "click", "3")
    p = wait_for(lambda p: "trace" in p, "the pixel trace")
    rows = {r["texture"]: r for r in p["trace"]["rows"] if r["tile"] < 0}
    check(len(rows) >= 15 and "gbuffer.albedo" in rows and "voxelize.radiance" in rows,
          "the trace lists every pass's textures (%d rows)" % len(p["trace"]["rows"]))
    out = rows.get("composite.color")
    want = [int((x - ix + 0.5) / iw * iw), int((1 - (y - iy + 0.5) / ih) * ih)]
    check(out is not None and out["texel"][:2] == want, "the output's texel is the clicked pixel: %s, want %s"
          % (out and out["texel"], want))
    check(out is not None and all(abs(out["value"][c] * 255 - on_screen[c]) <= 3 for c in range(3)),
          "the output's traced value is what the screen shows there: %s vs %s"
          % (out and [round(v * 255) for v in out["value"][:3]], on_screen))
    check("world" in p["trace"] and abs(p["trace"]["world"][1] + 1) < 0.05,
          "the clicked floor pixel's world position is on the floor (y = -1): %s" % p["trace"].get("world"))
    screenshot("trace.png")

finally:
    kiln.terminate()
    try:
        out, _ = kiln.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        kiln.kill()
        out, _ = kiln.communicate()
    print(out[-3000:])
    gl_errors = [l for l in out.splitlines() if "GL [" in l]
    check(not gl_errors, "no GL errors: %s" % gl_errors[:3])
    # SIGTERM: 128 + 15 once the handler is in (the layout saved), -15 before it is.
    check(kiln.returncode in (143, -15), "kiln ended by the test's SIGTERM, not by itself (exit %s)" % kiln.returncode)

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
