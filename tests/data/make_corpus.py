#!/usr/bin/env python3
"""Regenerates tests/data/good, tests/data/bad and tests/data/warn: tiny hand-made scene files.

Each bad file has exactly one defect, named by the file; the core test expects
InputError naming the file for every file in bad/. Each warn file lacks one part (a
texture, a .mtl) that the loader replaces by a fallback with a warning, or rejects with
--strict.
"""
import base64, json, math, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
GOOD, BAD, WARN = os.path.join(HERE, "good"), os.path.join(HERE, "bad"), os.path.join(HERE, "warn")


def png_rgb8(width, height, pixels):
    """A minimal 8-bit RGB PNG (no filter) of `pixels`, rows top to bottom."""
    raw = b"".join(b"\0" + bytes(c for p in pixels[y * width:(y + 1) * width] for c in p) for y in range(height))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def tri_buffer(positions=None, indices=(0, 1, 2)):
    positions = positions or [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    idx = b"".join(struct.pack("<H", i) for i in indices)
    idx += b"\0" * (-len(idx) % 4)
    return pos, idx


def gltf_doc(pos, idx, count=None, idx_count=None, extra=None):
    n = len(pos) // 12
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "tri"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"name": "m", "pbrMetallicRoughness": {"metallicFactor": 1.0, "roughnessFactor": 0.0}}],
        "buffers": [{"byteLength": len(pos) + len(idx)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n if count is None else count, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3 if idx_count is None else idx_count, "type": "SCALAR"},
        ],
    }
    if extra:
        extra(doc)
    return doc


def data_uri(b):
    return "data:application/octet-stream;base64," + base64.b64encode(b).decode()


def write_gltf(folder, name, doc, buf=None):
    if buf is not None:
        doc["buffers"][0]["uri"] = data_uri(buf)
    with open(os.path.join(folder, name), "w") as f:
        json.dump(doc, f, indent=1)


def glb_bytes(doc, bin_data):
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    bin_data += b"\0" * (-len(bin_data) % 4)
    total = 12 + 8 + len(js) + 8 + len(bin_data)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(js), 0x4E4F534A) + js +
            struct.pack("<II", len(bin_data), 0x004E4942) + bin_data)


def write(folder, name, data, mode="wb"):
    with open(os.path.join(folder, name), mode) as f:
        f.write(data)


def main():
    os.makedirs(GOOD, exist_ok=True)
    os.makedirs(BAD, exist_ok=True)
    os.makedirs(WARN, exist_ok=True)
    pos, idx = tri_buffer()
    buf = pos + idx

    # ---- good files --------------------------------------------------------------
    write_gltf(GOOD, "triangle.gltf", gltf_doc(pos, idx), buf)
    glb = glb_bytes(gltf_doc(pos, idx), buf)
    write(GOOD, "triangle.glb", glb)
    write(GOOD, "tetra.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", "w")
    write(GOOD, "tetra.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", "w")
    write(GOOD, "tetra.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
          "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
          "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", "w")
    stl = b"speculum tetra".ljust(80, b"\0") + struct.pack("<I", 4)
    P = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    for f in [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]:
        stl += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *P[i]) for i in f) + b"\0\0"
    write(GOOD, "tetra.stl", stl)

    # ---- bad glTF ----------------------------------------------------------------
    write(BAD, "empty.gltf", b"")
    write(BAD, "empty.glb", b"")
    write(BAD, "truncated.glb", glb[: len(glb) // 2])
    write(BAD, "truncated_header.glb", glb[:10])
    bad_magic = bytearray(glb); bad_magic[0:4] = b"XXXX"
    write(BAD, "bad_magic.glb", bytes(bad_magic))
    chunk_overrun = bytearray(glb); struct.pack_into("<I", chunk_overrun, 12, 1 << 30)
    write(BAD, "json_chunk_overrun.glb", bytes(chunk_overrun))
    write(BAD, "invalid_json.gltf", b'{"asset": {"version": "2.0"}, "nodes": [ {"mesh": 0,, ]')
    doc = gltf_doc(pos, idx); doc["buffers"][0]["uri"] = "does_not_exist.bin"
    write_gltf(BAD, "missing_bin.gltf", doc)
    _, bad_idx = tri_buffer(indices=(0, 1, 7))
    write_gltf(BAD, "index_out_of_range.gltf", gltf_doc(pos, bad_idx), pos + bad_idx)
    nan_pos, _ = tri_buffer(positions=[(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)])
    write_gltf(BAD, "nan_position.gltf", gltf_doc(nan_pos, idx), nan_pos + idx)
    inf_pos, _ = tri_buffer(positions=[(0, 0, 0), (1, 0, 0), (0, float("inf"), 0)])
    write(BAD, "inf_position.glb", glb_bytes(gltf_doc(inf_pos, idx), inf_pos + idx))

    def add_texture(d):
        d["images"] = [{"uri": "no_such_texture.png"}]
        d["textures"] = [{"source": 0}]
        d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    write_gltf(WARN, "missing_texture.gltf", gltf_doc(pos, idx, extra=add_texture), buf)

    def add_undecodable_texture(d):
        add_texture(d)
        d["images"] = [{"uri": "not_an_image.png"}]
    write_gltf(WARN, "undecodable_texture.gltf", gltf_doc(pos, idx, extra=add_undecodable_texture), buf)

    def require_draco(d):
        d["extensionsUsed"] = ["KHR_draco_mesh_compression"]
        d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write_gltf(BAD, "unsupported_extension.gltf", gltf_doc(pos, idx, extra=require_draco), buf)
    write(BAD, "unsupported_file_type.xyz", "not a scene\n", "w")

    def require_meshopt(d):
        # As a meshopt-compressed file has it: the view holds compressed bytes in the
        # extension, and a fallback buffer without a uri.
        d["extensionsUsed"] = ["EXT_meshopt_compression"]
        d["extensionsRequired"] = ["EXT_meshopt_compression"]
        d["bufferViews"][0]["extensions"] = {"EXT_meshopt_compression": {
            "buffer": 0, "byteLength": 36, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}}
    write_gltf(BAD, "meshopt_required.gltf", gltf_doc(pos, idx, extra=require_meshopt), buf)

    def draco_primitive(d):
        # As a Draco file has it: accessors without bufferViews, the mesh in the extension.
        require_draco(d)
        for a in d["accessors"]:
            del a["bufferView"]
        d["meshes"][0]["primitives"][0]["extensions"] = {
            "KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}
    write_gltf(BAD, "draco_required.gltf", gltf_doc(pos, idx, extra=draco_primitive), buf)

    def two_unsupported(d):
        d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"]
    write_gltf(BAD, "two_unsupported_extensions.gltf", gltf_doc(pos, idx, extra=two_unsupported), buf)

    # glTF 1.0: objects keyed by id, asset.version "1.0" (and a version-1 binary container).
    gltf1 = {
        "asset": {"version": "1.0"},
        "scene": "defaultScene",
        "scenes": {"defaultScene": {"nodes": ["node_0"]}},
        "nodes": {"node_0": {"meshes": ["mesh_0"]}},
        "meshes": {"mesh_0": {"primitives": [{"attributes": {"POSITION": "accessor_0"}, "mode": 4}]}},
        "accessors": {"accessor_0": {"bufferView": "bufferView_0", "byteOffset": 0, "componentType": 5126,
                                     "count": 3, "type": "VEC3"}},
        "bufferViews": {"bufferView_0": {"buffer": "buffer_0", "byteLength": len(pos), "byteOffset": 0}},
        "buffers": {"buffer_0": {"byteLength": len(pos), "uri": data_uri(pos)}},
    }
    write(BAD, "gltf_1_0.gltf", json.dumps(gltf1, indent=1), "w")
    js1 = json.dumps(gltf1).encode()
    js1 += b" " * (-len(js1) % 4)
    write(BAD, "gltf_1_0.glb", struct.pack("<IIIII", 0x46546C67, 1, 20 + len(js1), len(js1), 0) + js1)
    no_asset = dict(gltf1)
    del no_asset["asset"]
    write(BAD, "gltf_1_0_no_asset.gltf", json.dumps(no_asset, indent=1), "w")

    def cycle(d):
        d["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [2]}, {"children": [1]}]
    write_gltf(BAD, "node_cycle.gltf", gltf_doc(pos, idx, extra=cycle), buf)

    def self_child(d):
        d["nodes"] = [{"mesh": 0, "children": [0]}]
    write_gltf(BAD, "node_self_child.gltf", gltf_doc(pos, idx, extra=self_child), buf)
    write_gltf(BAD, "absurd_count.gltf", gltf_doc(pos, idx, count=1 << 40), buf)
    write_gltf(BAD, "accessor_past_buffer.gltf", gltf_doc(pos, idx, count=1000), buf)
    write_gltf(BAD, "absurd_index_count.gltf", gltf_doc(pos, idx, idx_count=4000000000), buf)

    def bad_view(d):
        d["bufferViews"][0]["byteLength"] = 1 << 31
    write_gltf(BAD, "bufferview_past_buffer.gltf", gltf_doc(pos, idx, extra=bad_view), buf)

    def bad_component(d):
        d["accessors"][0]["componentType"] = 5130
    write_gltf(BAD, "bad_component_type.gltf", gltf_doc(pos, idx, extra=bad_component), buf)

    def int_positions(d):
        d["accessors"][0]["componentType"] = 5125
    write_gltf(BAD, "wrong_position_type.gltf", gltf_doc(pos, idx, extra=int_positions), buf)

    def bad_accessor_ref(d):
        d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 42
    write_gltf(BAD, "accessor_index_out_of_range.gltf", gltf_doc(pos, idx, extra=bad_accessor_ref), buf)

    def bad_material(d):
        d["meshes"][0]["primitives"][0]["material"] = 9
    write_gltf(BAD, "material_index_out_of_range.gltf", gltf_doc(pos, idx, extra=bad_material), buf)

    def bad_node_mesh(d):
        d["nodes"][0]["mesh"] = 5
    write_gltf(BAD, "node_mesh_out_of_range.gltf", gltf_doc(pos, idx, extra=bad_node_mesh), buf)

    def nan_matrix(d):
        d["nodes"][0]["translation"] = [0, 1e39, 0]  # overflows float: infinite
    write_gltf(BAD, "infinite_transform.gltf", gltf_doc(pos, idx, extra=nan_matrix), buf)

    def no_meshes(d):
        d["nodes"] = [{"name": "empty"}]
    write_gltf(BAD, "no_triangles.gltf", gltf_doc(pos, idx, extra=no_meshes), buf)
    write(BAD, "not_json.gltf", b"\x89PNG\r\n\x1a\n binary junk")

    # ---- bad meshes --------------------------------------------------------------
    write(BAD, "empty.obj", b"")
    write(BAD, "no_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "w")
    write(BAD, "index_out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", "w")
    write(BAD, "nan_position.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "w")
    write(BAD, "empty.ply", b"")
    write(BAD, "absurd_count.ply", "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\n"
          "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
          "end_header\n0 0 0\n", "w")
    write(BAD, "truncated_binary.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
          b"property float x\nproperty float y\nproperty float z\nelement face 1\n"
          b"property list uchar int vertex_indices\nend_header\n" + struct.pack("<4f", 0, 0, 0, 1))
    write(BAD, "not_a_ply.ply", "hello\n", "w")
    # A binary point cloud (no face element) with an extra per-vertex property.
    write(BAD, "point_cloud.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
          b"property float x\nproperty float y\nproperty float z\nproperty float psz\nend_header\n"
          + struct.pack("<8f", 0, 0, 0, 1, 1, 0, 0, 1))
    # Property before any element: crashed OpenMesh's PLY reader before our header check.
    write(BAD, "property_before_element.ply", "ply\nformat ascii 1.0\n\xa6lement vertex 4\n"
          "property float x\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n", "w")
    write(BAD, "no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "w")
    write(BAD, "empty.off", b"")
    write(BAD, "absurd_count.off", "OFF\n1000000000 1000000000 0\n0 0 0\n", "w")
    write(BAD, "truncated.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n", "w")
    write(BAD, "index_out_of_range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "w")
    write(BAD, "empty.stl", b"")
    write(BAD, "truncated.stl", stl[:84 + 50 + 10])
    absurd_stl = bytearray(stl); struct.pack_into("<I", absurd_stl, 80, 0xFFFFFFFF)
    write(BAD, "absurd_count.stl", bytes(absurd_stl))

    # ---- OBJ with materials (good) and with missing parts (warn) --------------------
    # A unit quad in z=0 with uvs, two materials: "painted" (textured, Ns 98, emissive)
    # and "glass" (d 0.25, Ni 1.33, Pr 0.1, Pm 0.5). checker.png is 2x2: red, green /
    # blue, grey 128 (rows top to bottom).
    write(GOOD, "checker.png", png_rgb8(2, 2, [(255, 0, 0), (0, 255, 0), (0, 0, 255), (128, 128, 128)]))
    quad = ("mtllib quad.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "vn 0 0 1\n"
            "o quad\nusemtl painted\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"
            "o sliver\nusemtl glass\nf 1 2 5\n")
    write(GOOD, "quad.obj", quad, "w")
    write(GOOD, "quad.mtl",
          "newmtl painted\nKa 0 0 0\nKd 0.5 0.25 1.0\nKs 0.1 0.1 0.1\nNs 98\nKe 0.5 0 2\nillum 2\nmap_Kd checker.png\n\n"
          "newmtl glass\nKd 1 1 1\nd 0.25\nNi 1.33\nPr 0.1\nPm 0.5\n", "w")
    write(WARN, "missing_mtl.obj", quad.replace("quad.mtl", "no_such_library.mtl"), "w")
    write(WARN, "missing_map.obj", quad.replace("quad.mtl", "missing_map.mtl"), "w")
    write(WARN, "missing_map.mtl", "newmtl painted\nKd 0.5 0.25 1.0\nmap_Kd no_such_map.png\n\nnewmtl glass\nKd 1 1 1\n", "w")
    write(WARN, "outside_map.obj", quad.replace("quad.mtl", "outside_map.mtl"), "w")
    write(WARN, "outside_map.mtl", "newmtl painted\nKd 0.5 0.25 1.0\nmap_Kd ../good/checker.png\n\nnewmtl glass\nKd 1 1 1\n", "w")
    write(WARN, "undecodable_map.obj", quad.replace("quad.mtl", "undecodable_map.mtl"), "w")
    write(WARN, "undecodable_map.mtl", "newmtl painted\nKd 0.5 0.25 1.0\nmap_Kd not_an_image.png\n\nnewmtl glass\nKd 1 1 1\n", "w")
    write(WARN, "not_an_image.png", "this is not a PNG\n", "w")


if __name__ == "__main__":
    main()
