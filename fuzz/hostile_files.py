#!/usr/bin/env python3
"""Writes the large hostile OBJ/MTL files of docs/security.md ("Memory") into
a folder, each under 64 MB, for measuring `isr render`'s peak memory:

    python3 fuzz/hostile_files.py /tmp/hostile
    for f in /tmp/hostile/*.obj; do
      /usr/bin/time -f "%M KiB %e s $(basename $f)" target/release/isr render \
        --scene $f --frames 1 --width 48 --height 48 --rsm 64 --out /tmp/hostile/o.exr \
        2>&1 >/dev/null | tail -1
    done

The small hostile cases are built by the tests themselves (tests/obj_hostile).
"""
import math
import os
import random
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "/tmp/hostile"
os.makedirs(out, exist_ok=True)
TRIANGLE = "v 0 0 0\nv 1 0 0\nv 1 0 -1\n"


def write(name, text):
    with open(os.path.join(out, name), "w") as f:
        f.write(text)


# A library of 100 materials, named 20,000 times on lines of their own and
# 1,000,000 times on one 8 MB line (tobj merged it at each: 4.2 GB, abort).
write("lib.mtl", "".join(f"newmtl m{i}\nKd 0.5 0.5 0.5\n" for i in range(100)))
write("mtllib_lines.obj", TRIANGLE + "mtllib lib.mtl\n" * 20_000 + "usemtl m1\nf 1 2 3\n")
write("mtllib_one_line.obj", TRIANGLE + "mtllib" + " lib.mtl" * 1_000_000 + "\nusemtl m1\nf 1 2 3\n")

# 4 million distinct materials in a 64 MB library (5 GB, 31 s before).
with open(os.path.join(out, "materials.mtl"), "w") as f:
    for i in range(4_000_000):
        f.write(f"newmtl m{i}\n")
write("materials.obj", TRIANGLE + "mtllib materials.mtl\nusemtl m1\nf 1 2 3\n")

# 12 MB of groups sharing one triangle, 22 MB of material switches.
write("groups.obj", TRIANGLE + "".join(f"g g{i}\nf 1 2 3\n" for i in range(700_000)))
write("switches.obj", TRIANGLE + "mtllib lib.mtl\n" + "usemtl m1\nf 1 2 3\nusemtl m2\nf 1 3 2\n" * 520_000)

# A million warnings: unknown keys, duplicate materials, Kd above 1,
# map_Kd options, unknown statements and usemtl names.
with open(os.path.join(out, "warnings.mtl"), "w") as f:
    f.write("newmtl a\n")
    for i in range(400_000):
        f.write(f"key{i} 1\n")
    for i in range(60_000):
        f.write("Kd 2 2 2\nmap_Kd -s 1 1 1 missing.png\nnewmtl a\n")
    f.write("newmtl b\nKd 0.5 0.5 0.5\n")
write("warnings.obj", TRIANGLE + "mtllib warnings.mtl\nusemtl b\nf 1 2 3\n"
      + "".join(f"statement{i} 1\nusemtl nothing{i}\nf 1 2 3\n" for i in range(300_000)))

# Distinct vertices: 999 positions on a circle and 9,999 texture
# coordinates, faces of three corners that combine them anew: past the
# budget of 2^21 distinct vertices, refused at its line.
def circle(f, n):
    for k in range(n):
        a = 2 * math.pi * k / n
        f.write(f"v {math.cos(a):.5f} 0 {math.sin(a):.5f}\n")


with open(os.path.join(out, "distinct_over.obj"), "w") as f:
    circle(f, 999)
    f.write("".join(f"vt {k / 9999:.5f} 0.5\n" for k in range(9999)))
    for k in range(0, 2_400_000, 3):
        f.write("f" + "".join(f" {j % 999 + 1}/{j // 999 % 9999 + 1}" for j in (k, k + 1, k + 2)) + "\n")


# What costs the renderer most, within the budgets: triangles it must
# rasterize (large ones, every way, on a sphere) with distinct vertices,
# up to 2^20 triangles in one fan, or up to 2^21 vertices in faces of
# three new corners each.
def sphere(f, n):
    for _ in range(n):
        z = random.uniform(-1, 1)
        a = random.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        f.write(f"v {r * math.cos(a):.5f} {r * math.sin(a):.5f} {z:.5f}\n")


random.seed(2)
with open(os.path.join(out, "visible_fan.obj"), "w") as f:
    sphere(f, 20_000)
    f.write("".join(f"vt {k / 105:.4f} 0.5\n" for k in range(105)) + "vn 0 1 0\n")
    corners = (1 << 20) - 100
    f.write("f" + "".join(f" {random.randrange(1, 20_001)}/{k // 20_000 + 1}/1" for k in range(corners)) + "\n")
with open(os.path.join(out, "visible_faces.obj"), "w") as f:
    sphere(f, 20_000)
    f.write("".join(f"vt {k / 105:.4f} 0.5\n" for k in range(105)) + "vn 0 1 0\n")
    for k in range(0, (1 << 21) - 100, 3):
        f.write("f" + "".join(f" {random.randrange(1, 20_001)}/{(k + j) // 20_000 + 1}/1" for j in range(3)) + "\n")

# One polygon of 16 million two-byte corners: past the triangle budget.
write("fan_over.obj", "".join(f"v {math.cos(k):.4f} 0 {math.sin(k):.4f}\n" for k in range(9))
      + "f" + " 1 2 3 4 5 6 7 8 9" * 1_800_000 + "\n")

# Normals to compute at creases everywhere: 100,000 points on a sphere and
# a polygon through them in random order (every triangle turned its own
# way), up to the triangle budget of 2^20.
random.seed(1)
with open(os.path.join(out, "creases.obj"), "w") as f:
    n = 100_000
    for _ in range(n):
        z = random.uniform(-1, 1)
        a = random.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        f.write(f"v {r * math.cos(a):.5f} {r * math.sin(a):.5f} {z:.5f}\n")
    f.write("f" + "".join(f" {random.randrange(1, n + 1)}" for _ in range((1 << 20) - 100)) + "\n")

# An ordinary mesh: a grid of a million triangles (32 MB), its bumps
# steep enough to crease.
with open(os.path.join(out, "grid.obj"), "w") as f:
    n = 707
    for i in range(n + 1):
        for j in range(n + 1):
            f.write(f"v {i / n} {((i * 7 + j * 13) % 17) / 170} {-j / n}\n")
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j + 1
            f.write(f"f {a} {a + n + 1} {a + n + 2} {a + 1}\n")

for name in sorted(os.listdir(out)):
    print(f"{os.path.getsize(os.path.join(out, name)) / 2**20:6.1f} MiB  {name}")
