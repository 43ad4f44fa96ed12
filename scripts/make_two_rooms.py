#!/usr/bin/env python3
"""Writes scenes/two_rooms.gltf: two rooms side by side, split by a thin wall with a doorway,
lit by one spot light in the west room — for measuring how much light voxel cone tracing
leaks through a wall into the room that only the doorway should light.

Each room is 4 x 3 x 4 m inside; the wall between them is THIN thick (0.2 m: 1.5 voxels of
the default 64³ volume around the 8.4 m scene), the doorway 0.8 x 2.1 m near its south end.
The east room holds a grey block. The camera stands in the east (dark) room and looks at
the wall and through the doorway. Every part is a closed box (one-sided faces, flat
normals); the outer shell is closed, so no light comes from outside.

    scripts/make_two_rooms.py [out.gltf]

The dark room for kiln-bench-quality: --region dark_room=0.09,-0.01,-2.01,4.11,3.01,2.01
"""
import json
import sys

from gltf_boxes import look_rotation, scene

ROOM = 4.0          # each room's inside width (x) and depth (z)
HEIGHT = 3.0
SHELL = 0.2         # outer walls, floor slab and roof
THIN = 0.2          # the wall between the rooms
DOOR = (-1.6, -0.8, 2.1)  # the doorway: z from, z to, height

MATERIALS = {
    "floor": (0.50, 0.45, 0.40),
    "plaster": (0.80, 0.78, 0.74),
    "partition": (0.80, 0.78, 0.74),
    "block": (0.45, 0.45, 0.48),
}


def rooms():
    t = THIN / 2
    x0, x1 = -t - ROOM, t + ROOM
    z0, z1 = -ROOM / 2, ROOM / 2
    parts = {name: [] for name in MATERIALS}
    parts["floor"].append(((x0, -SHELL, z0), (x1, 0.0, z1)))
    parts["plaster"] += [((x0 - SHELL, -SHELL, z0 - SHELL), (x0, HEIGHT + SHELL, z1 + SHELL)),  # west
                         ((x1, -SHELL, z0 - SHELL), (x1 + SHELL, HEIGHT + SHELL, z1 + SHELL)),  # east
                         ((x0, -SHELL, z0 - SHELL), (x1, HEIGHT + SHELL, z0)),                  # north
                         ((x0, -SHELL, z1), (x1, HEIGHT + SHELL, z1 + SHELL)),                  # south
                         ((x0, HEIGHT, z0), (x1, HEIGHT + SHELL, z1))]                          # roof
    dz0, dz1, dh = DOOR
    parts["partition"] += [((-t, 0.0, z0), (t, HEIGHT, dz0)),      # north of the door
                           ((-t, 0.0, dz1), (t, HEIGHT, z1)),      # south of it
                           ((-t, dh, dz0), (t, HEIGHT, dz1))]      # the lintel
    parts["block"].append(((2.2, 0.0, 0.6), (3.0, 0.9, 1.4)))
    return parts


def gltf(parts):
    lights = [{"name": "west lamp", "type": "spot", "color": [1.0, 0.9, 0.75], "intensity": 40.0,
               "spot": {"innerConeAngle": 0.6, "outerConeAngle": 1.0}}]
    nodes = [{"name": "west lamp", "translation": [-THIN / 2 - ROOM / 2, HEIGHT - 0.2, 0.0],
              "rotation": look_rotation((0.0001, -1.0, 0.0)), "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    camera = {"name": "camera", "camera": 0, "translation": [3.8, 1.6, 1.8],
              "rotation": look_rotation((-1.0, -0.2, -0.55))}
    return scene("two rooms", "kiln scripts/make_two_rooms.py", MATERIALS, parts, lights, nodes, camera, yfov=1.1)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/two_rooms.gltf"
    with open(out, "w") as f:
        json.dump(gltf(rooms()), f, separators=(",", ":"))
    print(out)
