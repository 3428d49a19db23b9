#!/usr/bin/env python3
"""Writes a variant of a glTF scene standing on a large ground plane (issue 16).

The plane is one quad (4 vertices, 2 triangles) of side --size metres, centred
under the scene's bounds, its top face just below the scene's lowest point,
with a grey diffuse material (--albedo, 0.2 like the Bitterli skies' ground).
It is appended as the last mesh, node and material, so every mesh of the
original keeps its index and content: a TransGI model baked for the original
still matches those meshes (the plane needs its own bake, or is shaded
diffusely with --allow-unbaked).

The engine reads only files inside a scene's folder, so the original's
buffers, images and extras URIs are copied next to the new scene.gltf. Output
goes where you say (a build or out/ folder), never into the repository:

    python3 content/variants/ground_plane.py ../shared/scenes/bitterli-breakfast-room/scene.gltf \
        out/breakfast_ground --size 200
"""
import argparse
import base64
import json
import math
import os
import shutil
import struct
import sys


def quat_rotate(q, v):
    x, y, z, w = q
    # v' = v + 2 w (q x v) + 2 q x (q x v)
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    ccx = y * cz - z * cy
    ccy = z * cx - x * cz
    ccz = x * cy - y * cx
    return [v[0] + 2 * (w * cx + ccx), v[1] + 2 * (w * cy + ccy), v[2] + 2 * (w * cz + ccz)]


def node_points(doc, node_index, parent):
    """World-space corners of every mesh box under node_index."""
    node = doc["nodes"][node_index]
    if "matrix" in node:
        m = node["matrix"]
        local = lambda p: [m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12],
                           m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
                           m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14]]
    else:
        t = node.get("translation", [0, 0, 0])
        r = node.get("rotation", [0, 0, 0, 1])
        s = node.get("scale", [1, 1, 1])
        local = lambda p: [a + b for a, b in zip(quat_rotate(r, [p[0] * s[0], p[1] * s[1], p[2] * s[2]]), t)]
    to_world = lambda p: parent(local(p))
    points = []
    if "mesh" in node:
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            acc = doc["accessors"][prim["attributes"]["POSITION"]]
            lo, hi = acc["min"], acc["max"]
            for i in range(8):
                corner = [hi[a] if (i >> a) & 1 else lo[a] for a in range(3)]
                points.append(to_world(corner))
    for child in node.get("children", []):
        points += node_points(doc, child, to_world)
    return points


def scene_bounds(doc):
    """World-space bounds (lo, hi) of the default scene's meshes."""
    scene = doc["scenes"][doc.get("scene", 0)]
    points = []
    for n in scene["nodes"]:
        points += node_points(doc, n, lambda p: p)
    if not points:
        return None
    return [min(p[a] for p in points) for a in range(3)], [max(p[a] for p in points) for a in range(3)]


def copy_referenced_files(doc, src_dir, out_dir):
    """Copies what the scene refers to by relative URI (buffers, images, the
    environment map in the scene's extras) from src_dir into out_dir."""
    def copy_uri(uri):
        if uri.startswith("data:"):
            return
        dst = os.path.join(out_dir, uri)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copyfile(os.path.join(src_dir, uri), dst)
    for b in doc.get("buffers", []):
        if "uri" in b:
            copy_uri(b["uri"])
    for im in doc.get("images", []):
        if "uri" in im:
            copy_uri(im["uri"])
    env = doc["scenes"][doc.get("scene", 0)].get("extras", {}).get("environment", {})
    if "uri" in env:
        copy_uri(env["uri"])


def add_mesh_node(doc, scene, name, blob_parts, counts, albedo):
    """Appends one triangle mesh (positions, normals as float32 VEC3, uint32
    indices) in a new data: buffer, a grey material and a root node."""
    pos, nrm, idx = blob_parts
    blob = pos + nrm + idx
    buf = len(doc.setdefault("buffers", []))
    doc["buffers"].append({"uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode(),
                           "byteLength": len(blob)})
    views = doc.setdefault("bufferViews", [])
    v0 = len(views)
    views += [{"buffer": buf, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
              {"buffer": buf, "byteOffset": len(pos), "byteLength": len(nrm), "target": 34962},
              {"buffer": buf, "byteOffset": len(pos) + len(nrm), "byteLength": len(idx), "target": 34963}]
    vertex_count, index_count, lo, hi = counts
    accs = doc.setdefault("accessors", [])
    a0 = len(accs)
    accs += [{"bufferView": v0, "componentType": 5126, "count": vertex_count, "type": "VEC3", "min": lo, "max": hi},
             {"bufferView": v0 + 1, "componentType": 5126, "count": vertex_count, "type": "VEC3"},
             {"bufferView": v0 + 2, "componentType": 5125, "count": index_count, "type": "SCALAR"}]
    mats = doc.setdefault("materials", [])
    mats.append({"name": name, "pbrMetallicRoughness": {
        "baseColorFactor": [albedo, albedo, albedo, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    meshes = doc.setdefault("meshes", [])
    meshes.append({"name": name, "primitives": [
        {"attributes": {"POSITION": a0, "NORMAL": a0 + 1}, "indices": a0 + 2, "material": len(mats) - 1}]})
    doc["nodes"].append({"name": name, "mesh": len(meshes) - 1})
    scene["nodes"].append(len(doc["nodes"]) - 1)


def write_scene(doc, out_dir):
    out = os.path.join(out_dir, "scene.gltf")
    tmp = out + ".tmp"
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1)
    os.replace(tmp, out)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", help="input .gltf (with external or data: buffers)")
    ap.add_argument("out_dir", help="folder to write scene.gltf and the copied files into")
    ap.add_argument("--size", type=float, default=200.0, help="side of the square plane, metres (default 200)")
    ap.add_argument("--albedo", type=float, default=0.2, help="grey diffuse albedo (default 0.2)")
    ap.add_argument("--gap", type=float, default=0.001, help="how far below the scene's lowest point (default 1 mm)")
    ap.add_argument("--volume", action="store_true",
                    help="also add an authored TransGI probe volume tight around the original scene: an empty node "
                         "'ProbeVolume' whose extras.transgi_probe_volume is true, its scale the bounds' half extents")
    args = ap.parse_args()
    if not (args.size > 0 and math.isfinite(args.size)):
        sys.exit(f"{args.scene}: --size must be a positive number of metres, got {args.size}")
    if not (0 <= args.albedo <= 1):
        sys.exit(f"{args.scene}: --albedo must lie in [0, 1], got {args.albedo}")

    with open(args.scene) as f:
        doc = json.load(f)
    src_dir = os.path.dirname(os.path.abspath(args.scene))
    os.makedirs(args.out_dir, exist_ok=True)

    scene = doc["scenes"][doc.get("scene", 0)]
    bounds = scene_bounds(doc)
    if not bounds:
        sys.exit(f"{args.scene}: no mesh to stand on a ground plane")
    lo, hi = bounds
    cx, cz, y = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2]), lo[1] - args.gap
    h = 0.5 * args.size

    copy_referenced_files(doc, src_dir, args.out_dir)

    # The plane: one quad, counter-clockwise seen from above (+y).
    pos = [(cx - h, y, cz - h), (cx + h, y, cz - h), (cx + h, y, cz + h), (cx - h, y, cz + h)]
    parts = (b"".join(struct.pack("<3f", *p) for p in pos), struct.pack("<3f", 0.0, 1.0, 0.0) * 4,
             struct.pack("<6I", 0, 2, 1, 0, 3, 2))
    add_mesh_node(doc, scene, "GroundPlane", parts, (4, 6, [cx - h, y, cz - h], [cx + h, y, cz + h]), args.albedo)
    nodes = doc["nodes"]
    if args.volume:
        centre = [0.5 * (lo[a] + hi[a]) for a in range(3)]
        half = [0.5 * (hi[a] - lo[a]) for a in range(3)]
        nodes.append({"name": "ProbeVolume", "translation": centre, "scale": half,
                      "extras": {"transgi_probe_volume": True}})
        scene["nodes"].append(len(nodes) - 1)

    out = write_scene(doc, args.out_dir)
    print(f"{out}: {args.size:g} m ground plane at y = {y:.4f}, centred at ({cx:.3f}, {cz:.3f}); "
          f"scene bounds ({lo[0]:.3f}, {lo[1]:.3f}, {lo[2]:.3f}) - ({hi[0]:.3f}, {hi[1]:.3f}, {hi[2]:.3f})")


if __name__ == "__main__":
    main()
