#!/usr/bin/python3
"""Merges MeshLab projects of one mesh, taken from several camera stations, into one project.

    tests/tools/merge_projects.py OUT_DIR PROJECT_A.mlp PROJECT_B.mlp [...] [--prefixes c1 c2 ...]

Every input project must hold the same mesh (same file content: the vertex order must match, since
fits are compared per vertex) and each raster's light in an .lp beside it (lights.lp). The output
folder gets:
  - project.mlp: the first project's mesh entry and every raster of every project, labels and
    photo file names prefixed per project ("c1_light_000.png"), cameras unchanged;
  - lights.lp: every entry of every project's lights.lp under the prefixed name (directions in each
    raster's camera frame, as the .lp format has them: unchanged);
  - symbolic links to the mesh and, for each photo folder of a project (every sub-folder holding a
    file named like the project's photos, e.g. images/ and linear/), prefixed links to those photos,
    so that vbrdf_fit --photo-dir OUT_DIR/linear works as for a single project.
Nothing in the inputs is modified. Exit status 2 on bad input (message on stderr).
"""
import filecmp
import os
import sys
import xml.etree.ElementTree as ET


def fail(message):
    sys.stderr.write("merge_projects: " + message + "\n")
    sys.exit(2)


def read_lp(path):
    lines = [l.split() for l in open(path) if l.strip()]
    if not lines or len(lines[0]) != 1:
        fail(f"'{path}' does not start with the entry count")
    entries = {}
    for t in lines[1:]:
        if len(t) != 4:
            fail(f"'{path}': a line is not 'image x y z': {' '.join(t)}")
        entries[os.path.basename(t[0])] = t[1:]
    if len(entries) != int(lines[0][0]):
        fail(f"'{path}': the count says {lines[0][0]} entries, the file has {len(entries)}")
    return entries


def main(argv):
    prefixes = None
    if "--prefixes" in argv:
        i = argv.index("--prefixes")
        prefixes, argv = argv[i + 1:], argv[:i]
    if len(argv) < 3:
        fail("usage: merge_projects.py OUT_DIR A.mlp B.mlp [...] [--prefixes c1 c2 ...]")
    out, projects = os.path.abspath(argv[0]), [os.path.abspath(p) for p in argv[1:]]
    prefixes = prefixes or [f"c{i + 1}" for i in range(len(projects))]
    if len(prefixes) != len(projects) or len(set(prefixes)) != len(prefixes):
        fail("--prefixes needs one distinct prefix per project")
    if out in (os.path.dirname(p) for p in projects):
        fail("OUT_DIR must not be an input project's folder")
    os.makedirs(out, exist_ok=True)

    merged_root = None
    raster_group = None
    lights = []
    mesh_file = None
    for project, prefix in zip(projects, prefixes):
        folder = os.path.dirname(project)
        root = ET.parse(project).getroot()
        mesh = root.find("MeshGroup/MLMesh")
        if mesh is None:
            fail(f"'{project}' has no mesh")
        this_mesh = os.path.join(folder, mesh.get("filename"))
        if mesh_file is None:
            mesh_file = this_mesh
        elif not filecmp.cmp(mesh_file, this_mesh, shallow=False):
            fail(f"'{this_mesh}' differs from '{mesh_file}': the projects must share one mesh (same vertex order)")
        lp_path = os.path.join(folder, "lights.lp")
        if not os.path.isfile(lp_path):
            fail(f"no lights.lp beside '{project}'")
        lp = read_lp(lp_path)
        rasters = root.findall("RasterGroup/MLRaster")
        if not rasters:
            fail(f"'{project}' has no rasters")
        photo_names = set()
        for raster in rasters:
            plane = raster.find("Plane")
            name = os.path.basename(plane.get("fileName"))
            if name not in lp:
                fail(f"'{lp_path}' has no entry for '{name}'")
            photo_names.add(name)
            sub = os.path.dirname(plane.get("fileName"))
            plane.set("fileName", os.path.join(sub, f"{prefix}_{name}") if sub else f"{prefix}_{name}")
            raster.set("label", f"{prefix}_{raster.get('label')}")
            lights.append((plane.get("fileName"), lp[name]))
        # Photo folders: every sub-folder that holds all of this project's photo names.
        for entry in sorted(os.listdir(folder)):
            sub = os.path.join(folder, entry)
            if not os.path.isdir(sub) or not all(os.path.exists(os.path.join(sub, n)) for n in photo_names):
                continue
            os.makedirs(os.path.join(out, entry), exist_ok=True)
            for n in photo_names:
                link = os.path.join(out, entry, f"{prefix}_{n}")
                if os.path.lexists(link):
                    os.remove(link)
                os.symlink(os.path.join(sub, n), link)
        if merged_root is None:
            merged_root = root
            raster_group = root.find("RasterGroup")
            mesh_link = os.path.join(out, mesh.get("filename"))
            if os.path.lexists(mesh_link):
                os.remove(mesh_link)
            os.symlink(this_mesh, mesh_link)
        else:
            for raster in rasters:
                raster_group.append(raster)

    ET.ElementTree(merged_root).write(os.path.join(out, "project.mlp"), encoding="unicode")
    with open(os.path.join(out, "lights.lp"), "w") as f:
        f.write(f"{len(lights)}\n")
        for name, d in lights:
            f.write(f"{name} {' '.join(d)}\n")
    print(f"{out}/project.mlp: {len(lights)} rasters from {len(projects)} projects")


if __name__ == "__main__":
    main(sys.argv[1:])
