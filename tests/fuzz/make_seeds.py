#!/usr/bin/env python3
"""Writes the fuzz seeds that must be derived from the bundled content (test
scenes repacked as .glb or with data: URIs) or made by hand (a tiny HDR,
command lines), into tests/fuzz/corpus/<harness>/. Bundled files that are
seeds as they stand (environment maps, PNG textures, the level's Lua scripts)
are not copied: tests/fuzz/CMakeLists.txt and README.md pass them as extra
corpus paths. Run from the repository root:

    python3 tests/fuzz/make_seeds.py

tiny.jpg and tiny.tgm in the corpus are kept as they are (README.md says how
they were made), as are the crash-<what> inputs that fuzzing found.
"""
import base64
import json
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORPUS = os.path.join(ROOT, "tests", "fuzz", "corpus")
SCENES = os.path.join(ROOT, "content", "test_scenes")


def out(harness, name, data):
    d = os.path.join(CORPUS, harness)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def read(*parts):
    with open(os.path.join(*parts), "rb") as f:
        return f.read()


def glb(doc, binary):
    """A GLB container: header, JSON chunk, BIN chunk (both 4-byte padded)."""
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(js) + 8 + len(binary)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(js), b"JSON") + js +
            struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def scene_as_glb(folder, images=()):
    """A test scene's .gltf + .bin as one .glb, its PNG images moved into the BIN chunk."""
    doc = json.loads(read(SCENES, folder, "scene.gltf"))
    binary = bytearray(read(SCENES, folder, doc["buffers"][0]["uri"]))
    for i, img in enumerate(doc.get("images", [])):
        if img.get("uri", "").endswith(".png") and img["uri"] in images:
            png = read(SCENES, folder, img["uri"])
            binary += b"\0" * (-len(binary) % 4)
            doc["bufferViews"].append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(png)})
            binary += png
            doc["images"][i] = {"bufferView": len(doc["bufferViews"]) - 1, "mimeType": "image/png"}
    doc["buffers"] = [{"byteLength": len(binary)}]
    # An environment map would lie outside the GLB: the seed loads whole without it.
    for sc in doc.get("scenes", []):
        sc.get("extras", {}).pop("environment", None)
    return glb(doc, bytes(binary)), doc, bytes(binary)


def main():
    # glTF: two scenes as .glb, one as .gltf with a data: URI buffer, and a
    # minimal triangle with an embedded PNG texture.
    cornell, doc, binary = scene_as_glb("cornell_box")
    out("gltf", "cornell_box.glb", cornell)
    doc["buffers"] = [{"byteLength": len(binary),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(binary).decode()}]
    out("gltf", "cornell_box_data_uri.gltf", json.dumps(doc, separators=(",", ":")).encode())
    thick, _, _ = scene_as_glb("thick_room", images=("wallpaper.png",))
    out("gltf", "thick_room.glb", thick)
    tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<6f", 0, 0, 1, 0, 0, 1) + struct.pack("<3I", 0, 1, 2)
    png = read(SCENES, "object_textured", "checker.png")
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "translation": [0, 0, -2], "scale": [2, 2, 2]}, {"camera": 0, "children": [2]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "doubleSided": True,
                       "emissiveFactor": [1, 1, 1]}],
        "textures": [{"source": 0, "sampler": 0}], "samplers": [{"wrapS": 33648}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}],
        "buffers": [{"byteLength": len(tri), "uri": "data:application/octet-stream;base64," + base64.b64encode(tri).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 60, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5125, "count": 3, "type": "SCALAR"}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}}]}},
    }
    out("gltf", "triangle_textured.gltf", json.dumps(doc, separators=(",", ":")).encode())

    # A 2x1 Radiance HDR (the EXR seeds are the bundled environment maps).
    out("exr", "tiny.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n" + bytes([128, 64, 32, 129, 1, 2, 3, 120]))

    # Command lines, one token per line.
    for name, argv in {
        "render_transgi": ["--scene", "s.gltf", "--method", "transgi", "--preset", "realtime", "--gi-scale", "0.5",
                           "--probe-budget", "192", "--width", "640", "--exposure", "-1.5"],
        "flags_and_positional": ["--resume", "extra", "--seed", "18446744073709551615", "--hysteresis", "nan"],
        "bad_values": ["--width", "1e9", "--map-width", "3", "--direct", "maybe", "--width"],
    }.items():
        out("args", name, "\n".join(argv).encode())


if __name__ == "__main__":
    main()
