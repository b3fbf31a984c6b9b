#!/usr/bin/env python3
"""Collects raw seeds for each fuzz target into OUT/<target>/ (then run_short.sh --merge
minimizes them into tests/fuzz/corpus/<target>/ with libFuzzer's -merge=1).

Sources: tests/data/good, tests/data/bad, the small files of Debian's assimp-testmodels
(/usr/share/assimp/models), and hand-made SPRY files, images and scene specs. A glTF's
external buffer and an OBJ's .mtl are appended after the part marker (fuzz_entries.h), with
the reference renamed to the companion file the harness writes (fuzz.bin, fuzz.mtl)."""
import json, os, re, struct, subprocess, sys, tempfile
from pathlib import Path

MARKER = b"\n%%speculum-fuzz-part%%\n"
MAX_BYTES = 64 * 1024
ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
ASSIMP = Path("/usr/share/assimp/models")


def files(ext):
    out = []
    for base in (DATA / "good", DATA / "bad", ASSIMP):
        if base.exists():
            out += [p for p in sorted(base.rglob("*")) if p.is_file() and p.suffix.lower() == ext
                    and p.stat().st_size <= MAX_BYTES]
    return out


def put(out, target, name, data):
    d = out / target
    d.mkdir(parents=True, exist_ok=True)
    (d / re.sub(r"[^A-Za-z0-9._-]", "_", name)).write_bytes(data)


def gltf_seed(path):
    data = path.read_bytes()
    try:
        doc = json.loads(data)
        bufs = doc.get("buffers", [])
    except Exception:
        return data
    if isinstance(bufs, list) and bufs and isinstance(bufs[0], dict):
        uri = bufs[0].get("uri", "")
        if isinstance(uri, str) and uri and not uri.startswith("data:"):
            companion = path.parent / uri
            if companion.is_file() and companion.stat().st_size <= MAX_BYTES:
                bufs[0]["uri"] = "fuzz.bin"
                return json.dumps(doc).encode() + MARKER + companion.read_bytes()
    return data


def obj_seed(path):
    data = path.read_bytes()
    m = re.search(rb"^mtllib\s+(\S+)\s*$", data, re.M)
    if m:
        mtl = path.parent / m.group(1).decode(errors="replace")
        if mtl.is_file() and mtl.stat().st_size <= MAX_BYTES:
            return data[:m.start()] + b"mtllib fuzz.mtl" + data[m.end():] + MARKER + mtl.read_bytes()
    return data


def spry(rays, magic=b"SPRY", version=1, count=None):
    head = magic + struct.pack("<IQ", version, len(rays) if count is None else count)
    return head + b"".join(struct.pack("<8f", *r) for r in rays)


def main():
    out = Path(sys.argv[1])
    for target, ext in (("gltf", ".gltf"), ("glb", ".glb")):
        for p in files(ext):
            put(out, target, p.parent.name + "_" + p.name, gltf_seed(p) if ext == ".gltf" else p.read_bytes())
    for p in files(".obj"):
        put(out, "obj", p.parent.name + "_" + p.name, obj_seed(p))
    for target in ("ply", "off", "stl"):
        for p in files("." + target):
            put(out, target, p.parent.name + "_" + p.name, p.read_bytes())
    ray = (0, 0, 0, 0, 0, 0, 1, 1e30)
    for name, data in (("empty", spry([])), ("one", spry([ray])), ("three", spry([ray] * 3)),
                       ("bad_magic", spry([ray], magic=b"YRPS")), ("version2", spry([ray], version=2)),
                       ("count_too_big", spry([ray], count=2)), ("truncated", spry([ray])[:30])):
        put(out, "ray_file", name + ".spry", data)
    for p in files(".png") + files(".jpg") + files(".jpeg"):
        put(out, "image", p.parent.name + "_" + p.name, p.read_bytes())
    with tempfile.TemporaryDirectory() as tmp:
        for ext, fmt in ((".hdr", "float"), (".exr", "half"), (".tga", "uint8"), (".png", "uint16")):
            f = Path(tmp) / ("tiny" + ext)
            subprocess.run(["oiiotool", "--pattern", "checker:width=4:height=4", "8x4", "3",
                            "-d", fmt, "-o", str(f)], check=True)
            put(out, "image", "tiny" + ext, f.read_bytes())
    checker = (DATA / "good" / "checker.png").read_bytes()
    put(out, "image", "truncated.png", checker[:len(checker) // 2])
    put(out, "image", "not_an_image.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 999999 +X 999999\n")
    specs = ["sphere-in-room", "glossy-plane:size=2000", "mirror-corridor:size=1000",
             "living-room:size=3000", "glass-sphere:size=1k", "bowl:size=1500",
             "bumpy-sphere:size=2000,n=4,amplitude=0.1", "bumpy-sphere:n=1000", "bowl:size=1e12",
             "sphere-in-room:size=-1", "glossy-plane:size=abc", "bowl:color=1", "bowl:size",
             "spere-in-room", "bumpy-sphere:amplitude=nan", "bowl:size=1.5M"]
    for i, s in enumerate(specs):
        put(out, "scene_spec", f"spec{i}", s.encode())


if __name__ == "__main__":
    main()
