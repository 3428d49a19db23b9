#!/usr/bin/env python3
"""Writes a level standing on a terrain with copies of itself (issue 16).

The terrain is a --size metres square heightfield (--resolution cells a side),
rolling hills of up to --hills metres, flattened to just under the level's
floor within --flat metres of each copy. The copies are the level's root nodes
again, translated by each --copies offset (x,z pairs), so they share the
level's meshes: a TransGI model baked for the level still matches them, and
the terrain, added last, is shaded diffusely with --allow-unbaked. Output goes
where you say, never into the repository:

    python3 content/variants/terrain.py content/levels/living_room/scene.gltf out/level_terrain
"""
import argparse
import copy
import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ground_plane as gp  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("out_dir")
    ap.add_argument("--size", type=float, default=1000.0, help="terrain side, metres (default 1000)")
    ap.add_argument("--resolution", type=int, default=96, help="cells a side (default 96)")
    ap.add_argument("--hills", type=float, default=6.0, help="hill height, metres (default 6)")
    ap.add_argument("--flat", type=float, default=12.0, help="flat radius around each copy, metres (default 12)")
    ap.add_argument("--copies", default="40,25;-55,60;90,-70",
                    help="x,z offsets of the extra copies, ';'-separated (default 3 copies)")
    ap.add_argument("--albedo", type=float, default=0.25)
    args = ap.parse_args()
    if not (args.size > 0 and 2 <= args.resolution <= 1024 and args.hills >= 0 and args.flat >= 0):
        sys.exit(f"{args.scene}: --size > 0, --resolution in [2, 1024], --hills >= 0 and --flat >= 0 please")
    try:
        offsets = [(0.0, 0.0)] + [tuple(float(v) for v in c.split(",")) for c in args.copies.split(";") if c.strip()]
    except ValueError:
        sys.exit(f"{args.scene}: --copies must be x,z pairs separated by ';', got '{args.copies}'")
    if any(len(o) != 2 for o in offsets):
        sys.exit(f"{args.scene}: --copies must be x,z pairs separated by ';', got '{args.copies}'")

    with open(args.scene) as f:
        doc = json.load(f)
    os.makedirs(args.out_dir, exist_ok=True)
    gp.copy_referenced_files(doc, os.path.dirname(os.path.abspath(args.scene)), args.out_dir)
    scene = doc["scenes"][doc.get("scene", 0)]
    lo, hi = gp.scene_bounds(doc)
    floor = lo[1] - 0.001

    # Copies of every root node (and its subtree), translated.
    def clone(index, dx, dz, top):
        node = copy.deepcopy(doc["nodes"][index])
        if top:
            if "matrix" in node:
                node["matrix"][12] += dx
                node["matrix"][14] += dz
            else:
                t = node.get("translation", [0.0, 0.0, 0.0])
                node["translation"] = [t[0] + dx, t[1], t[2] + dz]
            node["name"] = f"{node.get('name', 'node')}@{dx:g},{dz:g}"
        node.pop("camera", None)  # one camera: the original's
        if "children" in node:
            node["children"] = [clone(c, dx, dz, False) for c in node["children"]]
        doc["nodes"].append(node)
        return len(doc["nodes"]) - 1
    roots = list(scene["nodes"])
    for dx, dz in offsets[1:]:
        for r in roots:
            scene["nodes"].append(clone(r, dx, dz, True))

    # The terrain: hills that flatten near each copy's footprint.
    cx, cz = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2])
    reach = 0.5 * math.hypot(hi[0] - lo[0], hi[2] - lo[2]) + args.flat

    def height(x, z):
        d = min(math.hypot(x - (cx + ox), z - (cz + oz)) for ox, oz in offsets)
        t = min(1.0, max(0.0, (d - reach) / 40.0))
        blend = t * t * (3 - 2 * t)
        hills = args.hills * (0.5 * math.sin(x / 37.0) * math.cos(z / 53.0) + 0.3 * math.sin((x + z) / 91.0) + 0.2)
        return floor + blend * hills

    n = args.resolution
    h = 0.5 * args.size
    step = args.size / n
    verts, normals = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = cx - h + i * step, cz - h + j * step
            y = height(x, z)
            # Central differences for the normal.
            e = 0.5 * step
            dx = (height(x + e, z) - height(x - e, z)) / (2 * e)
            dz = (height(x, z + e) - height(x, z - e)) / (2 * e)
            ln = math.sqrt(dx * dx + 1 + dz * dz)
            verts.append((x, y, z))
            normals.append((-dx / ln, 1 / ln, -dz / ln))
    idx = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            idx += [a, c, b, b, c, d]  # counter-clockwise seen from above
    parts = (b"".join(struct.pack("<3f", *v) for v in verts), b"".join(struct.pack("<3f", *v) for v in normals),
             struct.pack(f"<{len(idx)}I", *idx))
    ys = [v[1] for v in verts]
    gp.add_mesh_node(doc, scene, "Terrain", parts,
                     (len(verts), len(idx), [cx - h, min(ys), cz - h], [cx + h, max(ys), cz + h]), args.albedo)
    out = gp.write_scene(doc, args.out_dir)
    print(f"{out}: {len(offsets)} copies of the level on a {args.size:g} m terrain ({n}x{n} cells, "
          f"{len(idx) // 3} triangles, heights {min(ys):.2f} to {max(ys):.2f} m)")


if __name__ == "__main__":
    main()
