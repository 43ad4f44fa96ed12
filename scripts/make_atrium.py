#!/usr/bin/env python3
"""Writes scenes/atrium.gltf: a three-storey atrium, 37 x 15 x 22 m, made for checking Kiln
on a scene at architectural scale that nobody tuned the knobs on.

An open court under a skylight, galleries on two floors around it carried by columns, a
red and a blue hanging between the columns, a sun through the skylight and three spot
lights under the galleries. Every part is a box (closed, one-sided faces, flat normals);
the file is glTF 2.0 with its buffer embedded, and a camera at eye height.

    scripts/make_atrium.py [out.gltf]
"""
import base64
import json
import math
import struct
import sys

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


def box(lo, hi):
    """The 24 vertices (4 a face, outward normals) and 36 indices of an axis-aligned box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [
        ((1, 0, 0), [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)]),
        ((-1, 0, 0), [(x0, y0, z1), (x0, y1, z1), (x0, y1, z0), (x0, y0, z0)]),
        ((0, 1, 0), [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)]),
        ((0, -1, 0), [(x0, y0, z1), (x0, y0, z0), (x1, y0, z0), (x1, y0, z1)]),
        ((0, 0, 1), [(x1, y0, z1), (x1, y1, z1), (x0, y1, z1), (x0, y0, z1)]),
        ((0, 0, -1), [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)]),
    ]
    positions, normals, indices = [], [], []
    for n, quad in faces:
        base = len(positions)
        positions += quad
        normals += [n] * 4
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, indices


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
    blob = bytearray()
    views, accessors, primitives, materials = [], [], [], []

    def view(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(views) - 1

    for m, (name, rgb) in enumerate(MATERIALS.items()):
        materials.append({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [*rgb, 1.0],
                                                                  "metallicFactor": 0.0, "roughnessFactor": 0.9}})
        positions, normals, indices = [], [], []
        for lo, hi in parts[name]:
            p, n, i = box(lo, hi)
            indices += [len(positions) + k for k in i]
            positions += p
            normals += n
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        pv = view(b"".join(struct.pack("<3f", *p) for p in positions), 34962)
        nv = view(b"".join(struct.pack("<3f", *n) for n in normals), 34962)
        iv = view(b"".join(struct.pack("<I", i) for i in indices), 34963)
        accessors += [{"bufferView": pv, "componentType": 5126, "count": len(positions), "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": nv, "componentType": 5126, "count": len(normals), "type": "VEC3"},
                      {"bufferView": iv, "componentType": 5125, "count": len(indices), "type": "SCALAR"}]
        a = len(accessors) - 3
        primitives.append({"attributes": {"POSITION": a, "NORMAL": a + 1}, "indices": a + 2, "material": m})

    def look_rotation(forward):
        """The quaternion (x, y, z, w) turning −z to `forward` with +y kept up."""
        fx, fy, fz = forward
        yaw = math.atan2(-fx, -fz)
        pitch = math.asin(fy / math.sqrt(fx * fx + fy * fy + fz * fz))
        qy = (0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2))
        qx = (math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2))
        (x1, y1, z1, w1), (x2, y2, z2, w2) = qy, qx
        return [w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2]

    lights = [{"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 1.5}]
    nodes = [{"name": "atrium", "mesh": 0},
             {"name": "sun", "rotation": look_rotation((0.35, -1.0, 0.2)), "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    for k, x in enumerate((-12.0, 0.0, 12.0)):
        lights.append({"name": f"gallery {k}", "type": "spot", "color": [1.0, 0.8, 0.6], "intensity": 60.0,
                       "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.9}})
        nodes.append({"name": f"gallery {k}", "translation": [x, LEVELS[0] - WALL - 0.3, D / 2 - GALLERY / 2],
                      "rotation": look_rotation((0.0, -1.0, 0.0001)), "extensions": {"KHR_lights_punctual": {"light": k + 1}}})
    nodes.append({"name": "camera", "camera": 0, "translation": [-13.5, 1.7, 6.5],
                  "rotation": look_rotation((1.0, 0.3, -0.5))})
    return {
        "asset": {"version": "2.0", "generator": "kiln scripts/make_atrium.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
        "meshes": [{"name": "atrium", "primitives": primitives}],
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/atrium.gltf"
    with open(out, "w") as f:
        json.dump(gltf(atrium()), f, separators=(",", ":"))
    print(out)
