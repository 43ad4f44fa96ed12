"""Box-built glTF 2.0 scenes for Kiln's test and benchmark scenes (scripts/make_*.py):
axis-aligned boxes per material, merged into one mesh, written as one .gltf with its buffer
embedded. Every face is one-sided with a flat normal."""
import base64
import math
import struct


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


def scene(name, generator, materials, parts, lights, light_nodes, camera_node, yfov=1.0):
    """The glTF document: one mesh `name` of a primitive per material (`materials`: name →
    linear RGB; `parts`: name → [(lo, hi), ...]), the KHR_lights_punctual `lights` placed by
    `light_nodes` (in order), and a perspective camera placed by `camera_node`."""
    blob = bytearray()
    views, accessors, primitives, gltf_materials = [], [], [], []

    def view(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(views) - 1

    for m, (material, rgb) in enumerate(materials.items()):
        gltf_materials.append({"name": material, "pbrMetallicRoughness": {"baseColorFactor": [*rgb, 1.0],
                                                                          "metallicFactor": 0.0, "roughnessFactor": 0.9}})
        positions, normals, indices = [], [], []
        for lo, hi in parts[material]:
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

    nodes = [{"name": name, "mesh": 0}] + [dict(n) for n in light_nodes] + [dict(camera_node, camera=0)]
    return {
        "asset": {"version": "2.0", "generator": generator},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.1}}],
        "meshes": [{"name": name, "primitives": primitives}],
        "materials": gltf_materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
