#!/usr/bin/env python3
"""Writes a copy of a MeshLab project whose cameras are off as a real registration is: every
raster's principal point moved by (dx, dy) image pixels (x right, y down) and/or every camera turned
by a small angle about its own x (pitch), y (yaw) or z (roll, the optical axis) axis. File names
become absolute, so the copy may live anywhere; the input project is only read.

  perturb_cameras.py in.mlp out.mlp [--shift DX DY] [--rotate AXIS DEGREES] [--mesh PLY]

--mesh: the project's mesh replaced by PLY (a perturbed copy of it: vbrdf_perturb_mesh).
"""
import argparse
import math
import os
import sys
import xml.etree.ElementTree as ET


def rotate_rows(rows, axis, degrees):
    """Rows of a VCG rotation are the camera's axes (x right, y up, z back) in the world; turning the
    camera by `degrees` about one of its own axes mixes the other two rows."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    ri, rj = rows[i], rows[j]
    rows[i] = [c * u + s * v for u, v in zip(ri, rj)]
    rows[j] = [-s * u + c * v for u, v in zip(ri, rj)]
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--shift", nargs=2, type=float, default=(0.0, 0.0), metavar=("DX", "DY"))
    ap.add_argument("--rotate", nargs=2, default=None, metavar=("AXIS", "DEGREES"))
    ap.add_argument("--mesh", default=None)
    args = ap.parse_args()
    if os.path.abspath(args.input) == os.path.abspath(args.output):
        sys.exit("perturb_cameras.py: the output would overwrite the input project")
    tree = ET.parse(args.input)
    folder = os.path.dirname(os.path.abspath(args.input))
    root = tree.getroot()
    for mesh in root.iter("MLMesh"):
        mesh.set("filename", os.path.abspath(args.mesh) if args.mesh else os.path.join(folder, mesh.get("filename")))
    for raster in root.iter("MLRaster"):
        for plane in raster.iter("Plane"):
            plane.set("fileName", os.path.join(folder, plane.get("fileName")))
        cam = raster.find("VCGCamera")
        cx, cy = (float(v) for v in cam.get("CenterPx").split())
        # VCG pixels run up: an image shift of +dy (down) lowers CenterPx's y.
        cam.set("CenterPx", "%.10g %.10g" % (cx + args.shift[0], cy - args.shift[1]))
        if args.rotate:
            m = [float(v) for v in cam.get("RotationMatrix").split()]
            rows = [m[0:3], m[4:7], m[8:11]]
            rows = rotate_rows(rows, args.rotate[0], float(args.rotate[1]))
            for r in range(3):
                m[4 * r:4 * r + 3] = rows[r]
            cam.set("RotationMatrix", " ".join("%.10g" % v for v in m) + " ")
    tree.write(args.output)


if __name__ == "__main__":
    main()
