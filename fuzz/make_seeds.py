#!/usr/bin/env python3
"""Writes the seed corpora under fuzz/seeds/<target>/ (committed; small).

Seeds are small valid files: a bumpy height field with a step in every
scan format, the small real-world meshes and SVGs from tests/data, and
hand-written SVGs using every path command. The pipeline seeds follow the
layout documented in fuzz/src/lib.rs.

Run from anywhere: python3 fuzz/make_seeds.py
"""
import base64
import json
import math
import pathlib
import shutil
import struct

FUZZ = pathlib.Path(__file__).resolve().parent
REPO = FUZZ.parent
SEEDS = FUZZ / "seeds"
REAL = REPO / "tests" / "data" / "realworld"


def height_field(n=9, lo=90.0, hi=114.0):
    # Inside the Marlin build volume (0..220 mm), so the pipeline seeds
    # reach the G-code writer; the drawings are placed onto it by the
    # offset bytes (SVG y is flipped: 0..10 mm becomes -10..0).
    def z(x, y):
        s = 1.5 * math.sin(x / 3.0) + math.cos(y / 4.0) + 3.0
        return s + (2.0 if x > lo + 16.0 else 0.0)

    xs = [lo + (hi - lo) * i / (n - 1) for i in range(n)]
    verts = [(x, y, round(z(x, y), 4)) for y in xs for x in xs]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            tris.append((a, a + 1, a + n + 1))
            tris.append((a, a + n + 1, a + n))
    return verts, tris


def obj(v, t):
    s = "# bumpy height field\n"
    s += "".join(f"v {x} {y} {z}\n" for x, y, z in v)
    s += "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in t)
    return s.encode()


def ply_ascii(v, t):
    s = (
        f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty float x\n"
        f"property float y\nproperty float z\nelement face {len(t)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    s += "".join(f"{x} {y} {z}\n" for x, y, z in v)
    s += "".join(f"3 {a} {b} {c}\n" for a, b, c in t)
    return s.encode()


def ply_binary(v, t):
    h = (
        f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n"
        "property double x\nproperty double y\nproperty double z\n"
        f"element face {len(t)}\nproperty list uchar uint vertex_indices\nend_header\n"
    ).encode()
    body = b"".join(struct.pack("<3d", *p) for p in v)
    body += b"".join(struct.pack("<B3I", 3, *f) for f in t)
    return h + body


def cloud_seeds(v):
    """Point-cloud seeds for import_cloud: the first byte picks the name
    (0 .xyz, 1 .csv, 2 .pcd, 3 .ply; bit 2 adds an edge limit from the
    next byte)."""
    d = SEEDS / "import_cloud"
    d.mkdir(parents=True)
    xyz = "".join(f"{x} {y} {z}\n" for x, y, z in v).encode()
    csv = b"x,y,z,nx,ny,nz\n" + "".join(f"{x},{y},{z},0,0,1\n" for x, y, z in v).encode()
    n = len(v)
    head = lambda data: (f"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                         f"COUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA {data}\n").encode()
    binary = head("binary") + b"".join(struct.pack("<3f", *p) for p in v)
    cols = b"".join(struct.pack("<f", p[k]) for k in range(3) for p in v)
    lzf = b"".join(bytes([len(cols[i:i + 32]) - 1]) + cols[i:i + 32] for i in range(0, len(cols), 32))
    compressed = head("binary_compressed") + struct.pack("<II", len(lzf), len(cols)) + lzf
    ply = (f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\n"
           f"property float y\nproperty float z\nend_header\n").encode()
    ply += b"".join(struct.pack("<3f", *p) for p in v)
    for name, data in [("grid.xyz", b"\x00" + xyz), ("grid.csv", b"\x01" + csv),
                       ("grid_ascii.pcd", b"\x02" + head("ascii") + xyz),
                       ("grid_binary.pcd", b"\x02" + binary),
                       ("grid_compressed.pcd", b"\x02" + compressed),
                       ("grid_points.ply", b"\x03" + ply), ("grid_limit.xyz", b"\x04\x50" + xyz)]:
        (d / name).write_bytes(data)


def normal(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    ln = math.sqrt(sum(x * x for x in n)) or 1.0
    return [x / ln for x in n]


def stl_ascii(v, t):
    s = "solid bumps\n"
    for f in t:
        a, b, c = (v[k] for k in f)
        n = normal(a, b, c)
        s += f" facet normal {n[0]:.6e} {n[1]:.6e} {n[2]:.6e}\n  outer loop\n"
        for p in (a, b, c):
            s += f"   vertex {p[0]:.6e} {p[1]:.6e} {p[2]:.6e}\n"
        s += "  endloop\n endfacet\n"
    return (s + "endsolid bumps\n").encode()


def stl_binary(v, t):
    out = b"binary stl seed".ljust(80, b" ") + struct.pack("<I", len(t))
    for f in t:
        a, b, c = (v[k] for k in f)
        out += struct.pack("<3f", *normal(a, b, c))
        for p in (a, b, c):
            out += struct.pack("<3f", *p)
        out += b"\0\0"
    return out


def gltf_parts(v, t):
    # glTF is metres, +Y up: printer (X, Y, Z) is stored as (X, Z, -Y) / 1000.
    pos = [(x / 1000, z / 1000, -y / 1000) for x, y, z in v]
    pbytes = b"".join(struct.pack("<3f", *p) for p in pos)
    ibytes = b"".join(struct.pack("<3H", *f) for f in t)
    ibytes += b"\0" * (-len(ibytes) % 4)
    buf = pbytes + ibytes
    lo = [min(p[i] for p in pos) for i in range(3)]
    hi = [max(p[i] for p in pos) for i in range(3)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pbytes)},
            {"buffer": 0, "byteOffset": len(pbytes), "byteLength": 6 * len(t)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(t), "type": "SCALAR"},
        ],
    }
    return doc, buf


def gltf(v, t):
    doc, buf = gltf_parts(v, t)
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
    return json.dumps(doc).encode()


def glb(v, t):
    doc, buf = gltf_parts(v, t)
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    buf += b"\0" * (-len(buf) % 4)
    chunks = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(buf), b"BIN\0") + buf
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


SVG_HEAD = '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="10mm" height="10mm" viewBox="0 0 10 10">'
SVGS = {
    "line.svg": '<line x1="1" y1="5" x2="9" y2="5" stroke="black"/>',
    "polyline.svg": '<polyline points="1,1 9,1 9,9 1,9" fill="none" stroke="black"/>',
    "circle.svg": '<circle cx="5" cy="5" r="3" fill="none" stroke="black"/>',
    "ellipse_rect.svg": '<ellipse cx="5" cy="5" rx="4" ry="2" stroke="red"/><rect x="2" y="2" width="6" height="6" rx="1" stroke="blue" fill="none"/>',
    "path_all.svg": '<path d="M1 1 L3 1 H5 V3 C6 4 7 4 8 3 S9 1 9 2 Q8 6 6 6 T2 8 A2 1 30 0 1 4 9 Z m1 1 l1 0 h1 v1 c0 1 1 1 1 0 s1 -1 1 0 q1 1 0 1 t-1 1 a1 1 0 1 0 -2 0 z" fill="none" stroke="black"/>',
    "transform_use.svg": '<defs><path id="p" d="M0 0 L3 3"/></defs><g transform="translate(2 2) rotate(30) scale(1.5)"><use xlink:href="#p"/><use xlink:href="#p" transform="matrix(1 0 0 -1 0 4)"/></g>',
    "polygon_style.svg": '<style>.s{stroke:#000;fill:none}</style><polygon class="s" points="5,1 9,9 1,9"/><text x="1" y="1">t</text>',
}


def svg(body):
    return (SVG_HEAD + body + "</svg>\n").encode()


# One line of every construct the G-code reader handles (see src/gcode/read.rs).
GCODE_FEATURES = """%
; RepRap/Marlin
N1 G21*27
N2 G90 G0 X0 Y0 Z5 F3000
G1X1Y2Z.5E0.1 (inline) ; comment
M201 X1000 Y1000
M117 Printing (50%
G91
G1 X1 Y-1.5 Z+0.25
G90
G20
G1 X0.1 Y0.2
G21
G92 X0 Y0 Z0
G92
G92.2
G92.3
G92.1
G28 X Y
G1 X1 Y1 Z1
G53 G0 Z0
G29
$H
$J=G91 X1
/G1 X2
G10
G11
G4 P100
G17 G40 G49 G61 G64 G80 G94
G1 Z2
X3 Y3
M291 P"a ""quoted"" string" S1
' aerotech
G71 G76
$DO[0].X = 1
DWELL 0.5
HOME X Y Z
G70
G1 X1 // aerotech comment
%
"""


def gcode_seeds():
    d = SEEDS / "read_gcode"
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    for dialect in ("marlin", "aerotech", "grbl"):
        lines = (REPO / "tests" / "golden" / f"demo-{dialect}.gcode").read_text().splitlines(keepends=True)
        (d / f"demo-{dialect}-head-tail.gcode").write_text("".join(lines[:40] + lines[-6:]))
    (d / "features.gcode").write_text(GCODE_FEATURES)
    (d / "features-crlf.gcode").write_bytes(GCODE_FEATURES.replace("\n", "\r\n").encode())


def pipeline_input(fmt, flags, scan, svg_bytes, params=(68, 63, 46, 228, 233, 0, 128)):
    return bytes([fmt, flags, *params]) + struct.pack("<I", len(scan)) + scan + svg_bytes


def main():
    if SEEDS.exists():
        shutil.rmtree(SEEDS)
    v, t = height_field()
    scans = {
        "obj": [("bumps.obj", obj(v, t))],
        "ply": [("bumps_ascii.ply", ply_ascii(v, t)), ("bumps_binary.ply", ply_binary(v, t))],
        "stl": [("bumps_ascii.stl", stl_ascii(v, t)), ("bumps_binary.stl", stl_binary(v, t))],
        "gltf": [("bumps.gltf", gltf(v, t)), ("bumps.glb", glb(v, t))],
    }
    real = {
        "obj": ["box_UTF16BE.obj", "concave_polygon.obj", "number_formats.obj"],
        "ply": ["cube_binary.ply", "cube_uv.ply", "issue623.ply"],
        "stl": [],
        "gltf": ["Mesh_PrimitiveMode_00.gltf", "RecursiveNodes.gltf", "TwoBoxes-glTF1.gltf",
                 "BoxTextured-Embedded.gltf", "BoxTextured.glb", "BoxWithInfinites.glb"],
    }
    for fmt, files in scans.items():
        d = SEEDS / f"import_{fmt}"
        d.mkdir(parents=True)
        for name, data in files:
            (d / name).write_bytes(data)
        for name in real[fmt]:
            shutil.copy(REAL / "mesh" / name, d / name)
    d = SEEDS / "load_svg"
    d.mkdir(parents=True)
    for name, body in SVGS.items():
        (d / name).write_bytes(svg(body))
    for src in list((REPO / "tests" / "data" / "svg").glob("*.svg")) + list((REAL / "svg").glob("*.svg")):
        shutil.copy(src, d / src.name)
    d = SEEDS / "pipeline"
    d.mkdir(parents=True)
    fmt_scans = [(0, obj(v, t)), (1, ply_binary(v, t)), (2, stl_binary(v, t)), (3, gltf(v, t)), (4, glb(v, t))]
    for k, (fmt, scan) in enumerate(fmt_scans):
        for planner in range(5):
            name = list(SVGS)[(k + planner) % len(SVGS)]
            # Planner index: bits 0-1 and bit 5. The paper's three planners
            # (0-2) may come closer than tol on the bumpy field: their seeds
            # accept the risk (bit 4), so every seed reaches the writer.
            flags = (planner & 3) | ((planner >> 2) << 5) | (16 if planner < 3 else 0)
            data = pipeline_input(fmt, flags, scan, svg(SVGS[name]))
            (d / f"fmt{fmt}_planner{planner}_{name.removesuffix('.svg')}").write_bytes(data)
    # Bigger nozzle, tighter tolerance, rotated and scaled placement, risk accepted.
    data = pipeline_input(1, 3 | 16, ply_ascii(v, t), svg(SVGS["path_all.svg"]), (200, 255, 5, 228, 233, 45, 140))
    (d / "ply_guarded_rotated").write_bytes(data)
    gcode_seeds()
    cloud_seeds(v)
    total = sum(p.stat().st_size for p in SEEDS.rglob("*") if p.is_file())
    print(f"wrote seeds under {SEEDS} ({total} bytes)")


if __name__ == "__main__":
    main()
