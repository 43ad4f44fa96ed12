#!/usr/bin/python3
"""Regenerates every picture and plot in docs/ (and sim/figures/) from the build, so none
goes stale: the window's under Xvfb (this script starts xvfb-run itself when there is no
display), driven through kiln's --ui-probe with xdotool; the headless renders; and the
benchmarks' plots, whose titles say the size, the device and the date.

    scripts/docs_images.py [--build DIR] [--only NAME]... [--list] [--skip-slow]

NAME is a picture's file name without .png (see --list). The slow ones (the benchmark
plots: the growth runs and the quality sweep, about 25 minutes together on 2 cores) are
left out with --skip-slow. Pictures are written in place; `git diff --stat docs` shows
what changed. Run from anywhere; paths are the repository's.
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs")
MODELS = "/usr/share/assimp/models"  # Debian's assimp-testmodels
ENGINE = MODELS + "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
BOX_TEXTURED = MODELS + "/glTF2/BoxTextured-glTF/BoxTextured.gltf"
WINDOW_SIZE = "720x720"  # the image; with the panels' column the window is 1100x720
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from kiln_window import KilnWindow  # noqa: E402  (after the path is set)


def run(words, cwd=None):
    print("  $ " + " ".join(words), flush=True)
    subprocess.run(words, check=True, cwd=cwd or ROOT)


def headless(build, out, size, *extra):
    run([os.path.join(build, "bin", "kiln"), "--headless", "--size", size, "--out", out] + list(extra))


def write_json(path, value):
    with open(path, "w") as f:
        json.dump(value, f, indent=1)
    return path


def scene_with_models(work, name, models, **rest):
    scene = json.load(open(os.path.join(ROOT, "scenes", "cornell.json")))
    scene.pop("$schema", None)
    scene.update(rest)
    scene["models"] = models
    return write_json(os.path.join(work, name + ".json"), scene)


def turning_minus_z_to(d):
    """The unit quaternion (x, y, z, w) turning −z (where a glTF light shines) to d."""
    length = sum(c * c for c in d) ** 0.5
    d = [c / length for c in d]
    axis = [d[1], -d[0], 0.0]  # (0, 0, −1) × d
    w = 1.0 - d[2]  # 1 + (0, 0, −1)·d
    norm = (sum(c * c for c in axis) + w * w) ** 0.5
    return [c / norm for c in axis] + [w / norm]


# ---- the pictures: name -> how it is made ------------------------------------------------

def gi_pictures(build, work):
    """The default pipeline and three others at 720² (docs/pipelines.md)."""
    for name, pipeline in (("gi_default", "default"), ("gi_iso", "iso_mips"), ("gi_direct", "direct_only"),
                           ("voxels", "voxels")):
        yield name, lambda out, p=pipeline: headless(build, out, "720x720", "--pipeline",
                                                     os.path.join(ROOT, "pipelines", p + ".json"))


def scene_pictures(build, work):
    """glTF scenes (docs/scenes.md): the atrium, and a model three ways."""
    yield "scene_atrium", lambda out: headless(build, out, "512x512", "--scene",
                                               os.path.join(ROOT, "scenes", "atrium.gltf"))
    in_box = lambda: scene_with_models(work, "engine_box", [{"file": ENGINE, "position": [0, 0.15, -0.55],
                                                             "scale": 0.0016, "rotation_deg": [0, 30, 0]}])
    yield "scene_engine_box", lambda out: headless(build, out, "320x320", "--frames", "20", "--scene", in_box())
    placed = lambda: scene_with_models(
        work, "box_textured", [{"file": BOX_TEXTURED, "fit": True, "scale": 0.45, "rotation_deg": [0, 35, 0],
                                "position": [0, 0, -0.2]}],
        tumblers=[{"position": [-0.55, 0.35], "color": [0.9, 0.15, 0.12]},
                  {"position": [0.55, 0.3], "color": [0.25, 0.35, 0.8]}], marbles=[], fireballs=[])
    yield "scene_box_textured", lambda out: headless(build, out, "320x320", "--scene", placed())

    def alone():
        # A glTF file of lights only: a sun from above left and a blue point light.
        lights = write_json(os.path.join(work, "lights.gltf"), {
            "asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [
                {"type": "directional", "intensity": 3.0, "color": [1.0, 0.96, 0.9]},
                {"type": "point", "intensity": 4.0, "color": [0.35, 0.55, 1.0]}]}},
            "scenes": [{"nodes": [0, 1]}], "scene": 0,
            "nodes": [{"extensions": {"KHR_lights_punctual": {"light": 0}},
                       "rotation": turning_minus_z_to([0.5, -0.8, -0.3])},  # from above left
                      {"extensions": {"KHR_lights_punctual": {"light": 1}}, "translation": [0.7, 0.5, 0.8]}]})
        return write_json(os.path.join(work, "engine_alone.json"), {
            "box": {"walls": False}, "tumblers": [], "marbles": [], "fireballs": [],
            "models": [{"file": ENGINE, "fit": True}, {"file": lights}]})
    yield "scene_engine_alone", lambda out: headless(build, out, "320x320", "--scene", alone())


def window_pictures(build, work):
    """The window at 1100x720 (README, docs/debug_view.md)."""
    kiln = os.path.join(build, "bin", "kiln")

    def shot(out, extra, act):
        config = tempfile.mkdtemp(dir=work)  # ImGui's ini: the first-run layout every time
        w = KilnWindow(kiln, ["--size", WINDOW_SIZE, "--budget", "0"] + extra, os.path.join(work, "window"),
                       env={"XDG_CONFIG_HOME": config}, first_frames=30)
        try:
            act(w)
            w.screenshot(out)
        finally:
            w.close()

    # The hero: the default frame once the tumblers have settled, the panels beside it.
    yield "window", lambda out: shot(out, [], lambda w: w.wait_for(lambda p: p["frame"] >= 240, "240 frames", 600))

    def texture(w):  # a voxel slice in the texture window, the readout under the mouse
        w.frames_later(10)
        x0, y0, x1, y1 = w.probe()["widgets"]["texture-canvas"]
        w.hover(x0 + (x1 - x0) * 0.45, y0 + (y1 - y0) * 0.6)
        w.wait_for(lambda p: "readout" in p, "the readout")
    yield "texture_window", lambda out: shot(out, ["--view", "voxelize.radiance"], texture)
    yield "graph_view", lambda out: shot(out, [], lambda w: (w.click("show-graph"), w.frames_later(10)))

    def compare(w):  # the default against the reference, once the reference has some paths
        w.click("show-compare")
        w.wait_for(lambda p: p["compare"].get("errors", {}).get("reference_paths", 0) >= 64, "64 reference paths", 600)
    yield "compare_view", lambda out: shot(out, [], compare)


def plot_pictures(build, work):
    """The benchmarks' figures (slow): copied from the run's output beside their CSV."""
    def growth(kind, counts):
        def make(out):
            bench_out = os.path.join(work, "growth_" + kind)
            run([os.path.join(build, "bin", "kiln-bench-render"), "--grow", kind + "=" + counts, "--out", bench_out])
            shutil.copy(os.path.join(bench_out, "growth.png"), out)
            shutil.copy(os.path.join(bench_out, "growth.csv"), out[:-4] + ".csv")
        return make
    yield "growth_fireballs", growth("fireballs", "2,10,25,50")
    yield "growth_marbles", growth("marbles", "3,25,50,100")

    def quality(out):  # the README's error table and its plot (its command, word for word)
        bench_out = os.path.join(work, "quality")
        also = ["bench/pipelines/default_before_feedback.json", "bench/pipelines/default_before_fire.json",
                "bench/pipelines/default_before_22.json", "pipelines/course.json", "pipelines/iso_mips.json",
                "pipelines/normal_cones.json"]
        run([os.path.join(build, "bin", "kiln-bench-quality"), "--spp", "512", "--out", bench_out] +
            [w for a in also for w in ("--also", a)])
        shutil.copy(os.path.join(bench_out, "quality.png"), out)
        shutil.copy(os.path.join(bench_out, "quality.csv"), out[:-4] + ".csv")
    yield "quality128", quality

    def simulation(out):
        bench_out = os.path.join(work, "sim")
        run([os.path.join(build, "bin", "kiln-sim"), "bench", "--out", bench_out])
        for name in ("sim_time_vs_error.png", "sim_error_vs_dt.png", "sim_rocking.csv"):
            shutil.copy(os.path.join(bench_out, name), os.path.join(os.path.dirname(out), name))
    yield "sim_time_vs_error", simulation  # writes sim_error_vs_dt.png beside it


GROUPS = [(gi_pictures, DOCS, False), (scene_pictures, DOCS, False), (window_pictures, DOCS, False),
          (plot_pictures, DOCS, True)]
ELSEWHERE = {"sim_time_vs_error": os.path.join(ROOT, "sim", "figures")}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"), help="the build tree (default build/)")
    parser.add_argument("--only", action="append", default=[], help="a picture's name (repeatable)")
    parser.add_argument("--list", action="store_true", help="name the pictures and exit")
    parser.add_argument("--skip-slow", action="store_true", help="leave out the benchmark plots")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="kiln-docs-")
    pictures = []
    for group, folder, slow in GROUPS:
        for name, make in group(os.path.abspath(args.build), work):
            pictures.append((name, os.path.join(ELSEWHERE.get(name, folder), name + ".png"), make, slow))
    if args.list:
        for name, out, _, slow in pictures:
            print("%-20s %s%s" % (name, os.path.relpath(out, ROOT), "  (slow)" if slow else ""))
        return 0
    unknown = set(args.only) - {p[0] for p in pictures}
    if unknown:
        sys.exit("docs_images.py: no picture named %s (--list names them)" % ", ".join(sorted(unknown)))
    chosen = [p for p in pictures if (p[0] in args.only if args.only else not (args.skip_slow and p[3]))]
    needs_display = any(make.__qualname__.startswith("window_pictures") for _, _, make, _ in chosen)
    if needs_display and not os.environ.get("DISPLAY"):
        # Every window picture at 1100x720 needs a screen at least that large.
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", sys.executable] + sys.argv)
    for name, out, make, _ in chosen:
        started = time.time()
        print("%s:" % os.path.relpath(out, ROOT), flush=True)
        make(out)
        print("  wrote %s (%.0f s)" % (os.path.relpath(out, ROOT), time.time() - started), flush=True)
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
