#!/usr/bin/env python3
"""Writes scenes/atrium.gltf: a three-storey atrium, 37 x 15 x 22 m, made for checking Kiln
on a scene at architectural scale that nobody tuned the knobs on.

An open court under a skylight, galleries on two floors around it carried by columns, a
red and a blue hanging between the columns, a sun through the skylight and three spot
lights under the galleries. Every part is a box (closed, one-sided faces, flat normals);
the file is glTF 2.0 with its buffer embedded, and a camera at eye height.

    scripts/make_atrium.py [out.gltf]
"""
import json
import sys

from gltf_boxes import look_rotation, scene

W, H, D = 37.0, 15.0, 22.0      # outer size: x, y, z
WALL = 0.4                      # wall, slab and roof thickness
GALLERY = 3.0                   # gallery depth
LEVELS = (5.0, 10.0)            # gallery floors
COLUMN = 0.6
COLUMN_STEP = 4.0

MATERIALS = {
    "floor": (0.55, 0.53, 0.50),
    "plaster": (0.78, 0.70, 0.58),
    "stone": (0.62, 0.60, 0.57),
    "red": (0.70, 0.12, 0.10),
    "blue": (0.12, 0.22, 0.65),
}


def atrium():
    parts = {name: [] for name in MATERIALS}
    hx, hz = W / 2, D / 2
    parts["floor"].append(((-hx, -WALL, -hz), (hx, 0.0, hz)))
    # Outer walls, inside faces at ±hx, ±hz.
    parts["plaster"] += [((-hx - WALL, -WALL, -hz - WALL), (-hx, H, hz + WALL)),
                         ((hx, -WALL, -hz - WALL), (hx + WALL, H, hz + WALL)),
                         ((-hx, -WALL, -hz - WALL), (hx, H, -hz)),
                         ((-hx, -WALL, hz), (hx, H, hz + WALL))]
    # The court: the galleries' inner edge.
    cx, cz = hx - GALLERY, hz - GALLERY
    for y in LEVELS + (H,):
        # A ring slab around the court (at the roof: the roof around the skylight).
        parts["stone"] += [((-hx, y - WALL, -hz), (hx, y, -cz)), ((-hx, y - WALL, cz), (hx, y, hz)),
                           ((-hx, y - WALL, -cz), (-cx, y, cz)), ((cx, y - WALL, -cz), (hx, y, cz))]
    # Columns along the court's edge, floor to roof.
    c = COLUMN / 2
    xs = [-cx + i * COLUMN_STEP for i in range(int(2 * cx / COLUMN_STEP) + 1)]
    zs = [-cz + i * COLUMN_STEP for i in range(int(2 * cz / COLUMN_STEP) + 1)]
    spots = {(x, z) for x in xs for z in (-cz, cz)} | {(x, z) for x in (-cx, cx) for z in zs}
    for x, z in sorted(spots):
        parts["stone"].append(((x - c, 0.0, z - c), (x + c, H - WALL, z + c)))
    # Two hangings between columns on the first gallery: red on the −z side, blue on +x.
    parts["red"].append(((-6.0, LEVELS[0] + 0.5, -cz - 0.05), (6.0, LEVELS[1] - 1.0, -cz + 0.05)))
    parts["blue"].append(((cx - 0.05, LEVELS[0] + 0.5, -4.0), (cx + 0.05, LEVELS[1] - 1.0, 4.0)))
    return parts


def gltf(parts):
    lights = [{"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 1.5}]
    nodes = [{"name": "sun", "rotation": look_rotation((0.35, -1.0, 0.2)), "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    for k, x in enumerate((-12.0, 0.0, 12.0)):
        lights.append({"name": f"gallery {k}", "type": "spot", "color": [1.0, 0.8, 0.6], "intensity": 60.0,
                       "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.9}})
        nodes.append({"name": f"gallery {k}", "translation": [x, LEVELS[0] - WALL - 0.3, D / 2 - GALLERY / 2],
                      "rotation": look_rotation((0.0, -1.0, 0.0001)), "extensions": {"KHR_lights_punctual": {"light": k + 1}}})
    camera = {"name": "camera", "camera": 0, "translation": [-13.5, 1.7, 6.5], "rotation": look_rotation((1.0, 0.3, -0.5))}
    return scene("atrium", "kiln scripts/make_atrium.py", MATERIALS, parts, lights, nodes, camera)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/atrium.gltf"
    with open(out, "w") as f:
        json.dump(gltf(atrium()), f, separators=(",", ":"))
    print(out)
