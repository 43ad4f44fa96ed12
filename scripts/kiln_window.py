"""Driving kiln's window from a script, as a user would: started under an X server, its
widgets found through --ui-probe (the JSON file it rewrites every frame saying where each
widget is), clicked and typed at with xdotool, photographed with ImageMagick's `import`.
Used by scripts/docs_images.py and the window tests (tests/window/).
"""
import json
import os
import subprocess
import time


class KilnWindow:
    """One running `kiln` window. `args` are kiln's own (--size, --scene, ...); --ui-probe
    is added. The constructor returns once the window has drawn `first_frames` frames."""

    def __init__(self, kiln, args, workdir, env=None, first_frames=3, timeout=180):
        self.workdir = workdir
        os.makedirs(workdir, exist_ok=True)
        self.probe_file = os.path.join(workdir, "probe.json")
        if os.path.exists(self.probe_file):
            os.remove(self.probe_file)
        self.process = subprocess.Popen([kiln, "--ui-probe", self.probe_file] + list(args),
                                        env=dict(os.environ, **(env or {})), cwd=workdir,
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        # A deadline, not a count: the first frames compile every shader on llvmpipe.
        self.wait_for(lambda p: p["frame"] >= first_frames, "the first frames", timeout)
        self.id = subprocess.run(["xdotool", "search", "--sync", "--name", "^Kiln$"], check=True,
                                 capture_output=True, text=True).stdout.split()[0]

    def probe(self, timeout=120):
        deadline = time.time() + timeout
        while time.time() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError("kiln exited:\n" + self.process.stdout.read()[-2000:])
            try:
                with open(self.probe_file) as f:
                    return json.load(f)
            except (OSError, ValueError):
                time.sleep(0.1)
        raise RuntimeError("no probe file after %d s" % timeout)

    def wait_for(self, predicate, what, timeout=120):
        deadline = time.time() + timeout
        while time.time() < deadline:
            p = self.probe()
            if predicate(p):
                return p
            time.sleep(0.2)
        raise RuntimeError("timed out waiting for " + what)

    def frames_later(self, n=3, timeout=120):
        """The probe once the window has drawn n more frames (what was done has landed)."""
        start = self.probe()["frame"]
        return self.wait_for(lambda p: p["frame"] >= start + n, "%d frames" % n, timeout)

    def xdotool(self, *args):
        subprocess.run(["xdotool"] + [str(a) for a in args], check=True)

    def centre(self, widget):
        x0, y0, x1, y1 = self.probe()["widgets"][widget]
        return int((x0 + x1) / 2), int((y0 + y1) / 2)

    def hover(self, x, y):
        self.xdotool("mousemove", "--window", self.id, int(x), int(y))
        time.sleep(0.2)  # ImGui sees the hover a frame before the click

    def click(self, widget, button=1):
        self.hover(*self.centre(widget))
        self.xdotool("click", button)
        return self.frames_later()

    def key(self, name):
        self.xdotool("key", "--window", self.id, name)
        return self.frames_later()

    def screenshot(self, path):
        subprocess.run(["import", "-window", self.id, path], check=True)
        return path

    def close(self):
        self.process.terminate()
        try:
            self.process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.communicate()
