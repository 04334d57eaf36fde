"""The bad-input corpus: each case breaks, or makes odd, a copy of a sample project the
way real captures do, and says what the run must give.

A case is `Case(name, group, outcome, what, edit)`:
  outcome "fail": meshlabserver exits non-zero, its output contains every string `edit` returns
          (file, raster or parameter named, and the remedy), nothing is written;
  outcome "sane": meshlabserver exits 0 and writes a complete result (every vertex, finite values,
          most vertices coloured), its log contains every string `edit` returns.
Every case: the inputs are byte-for-byte unchanged. `edit(ctx)` changes the copy in ctx.proj_dir
(and ctx.values: filter parameters; ctx.env: environment) and returns the expected strings.
`what` is the one-line description in docs/testing.md#the-corpus of what the case gets.
"""
import json
import os
import re
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET

import numpy as np

import e2e_lib as lib
import run_e2e

FILTER = "Vertex BRDF: fit per-vertex reflectance"


class Case:
    def __init__(self, name, group, outcome, what, edit, in_filter=True, min_coloured=0.4):
        self.name, self.group, self.outcome, self.what, self.edit = name, group, outcome, what, edit
        self.in_filter = in_filter  # a "fail" reported by the filter (else by meshlabserver itself)
        self.min_coloured = min_coloured


class Context:
    """A broken copy of a project: proj_dir, mlp, lp (the project's .lp), mesh; photo_tool (the
    vbrdf_photo_variant binary); values (filter parameters), env (extra environment)."""

    def __init__(self, proj_dir, mlp, lp, photo_tool, out_dir):
        self.proj_dir, self.mlp, self.lp, self.photo_tool, self.out_dir = proj_dir, mlp, lp, photo_tool, out_dir
        self.values, self.env = {}, {}
        self.pre_existing = {}  # output files placed before the run: name -> bytes (kept if the run fails)

    @property
    def mesh(self):
        root = ET.parse(self.mlp).getroot()
        name = root.find("./MeshGroup/MLMesh").get("filename")
        return os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(self.mlp)), name))

    def rasters(self):
        """[(label, photo path as written)]."""
        return run_e2e.rasters(self.mlp)

    def photo(self, i):
        return os.path.join(self.proj_dir, self.rasters()[i][1])

    def variant(self, mode, src, dst):
        self.variants(mode, [(src, dst)])

    def variants(self, mode, pairs):
        """vbrdf_photo_variant `mode` on [(src, dst)], in one run."""
        subprocess.run([self.photo_tool, mode] + [p for pair in pairs for p in pair], check=True)


# ---------------------------------------------------------------------------------------------
# Helpers

def read_lp(path):
    lines = [l.split() for l in lib.read_text(path).splitlines() if l.strip()]
    return [(t[0], t[1:4]) for t in lines[1:]]


def write_lp(path, entries, newline="\n", bom=False, count=None):
    text = f"{len(entries) if count is None else count}{newline}"
    text += "".join(f"{name} {' '.join(d)}{newline}" for name, d in entries)
    with open(path, "wb") as f:
        f.write((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8"))


def edit_mesh(path, edit):
    ply = lib.read_ply(path)
    vertex, faces = edit(ply.vertex.copy(), ply.faces)
    lib.write_ply(path, vertex, faces)


def raster_camera(ctx, index, edit):
    """Applies edit(dict of <VCGCamera> attributes) to raster `index` of the .mlp (text edit)."""
    text = lib.read_text(ctx.mlp)
    label = ctx.rasters()[index][0]
    start = text.index(f'<MLRaster label="{label}"')
    cam_start = text.index("<VCGCamera", start)
    cam_end = text.index("/>", cam_start)
    attrs = dict(re.findall(r'(\w+)="([^"]*)"', text[cam_start:cam_end]))
    edit(attrs)
    cam = "<VCGCamera " + " ".join(f'{k}="{v}"' for k, v in attrs.items())
    lib.write_text(ctx.mlp, text[:cam_start] + cam + text[cam_end:])
    return label


def convert_photos(ctx, mode, ext, indices=None):
    """Replaces photos by vbrdf_photo_variant `mode` ones named *.ext; the .mlp and .lp follow."""
    rasters = ctx.rasters()
    text, lp = lib.read_text(ctx.mlp), lib.read_text(ctx.lp)
    renamed = []
    for i, (_, photo) in enumerate(rasters):
        if indices is None or i in indices:
            renamed.append((photo, os.path.splitext(photo)[0] + "." + ext))
    ctx.variants(mode, [(os.path.join(ctx.proj_dir, a), os.path.join(ctx.proj_dir, b)) for a, b in renamed])
    for photo, new in renamed:
        if new != photo:
            os.remove(os.path.join(ctx.proj_dir, photo))
            text = text.replace(f'fileName="{photo}"', f'fileName="{new}"')
            lp = lp.replace(photo, new)
    lib.write_text(ctx.mlp, text)
    lib.write_text(ctx.lp, lp)


def keep_rasters(ctx, keep):
    """Keeps only the rasters whose index is in `keep` (and their .lp entries)."""
    text = lib.read_text(ctx.mlp)
    blocks = re.findall(r"\s*<MLRaster .*?</MLRaster>", text, flags=re.S)
    names = []
    for i, b in enumerate(blocks):
        if i in keep:
            names.append(os.path.basename(re.search(r'fileName="([^"]*)"', b).group(1)))
        else:
            text = text.replace(b, "", 1)
    lib.write_text(ctx.mlp, text)
    write_lp(ctx.lp, [e for e in read_lp(ctx.lp) if os.path.basename(e[0]) in names])


def add_exif_orientation(jpeg, orientation):
    """The JPEG with an EXIF APP1 segment holding only Orientation (tag 0x0112) after SOI."""
    ifd = struct.pack("<H", 1) + struct.pack("<HHIHH", 0x0112, 3, 1, orientation, 0) + struct.pack("<I", 0)
    payload = b"Exif\x00\x00" + b"II*\x00" + struct.pack("<I", 8) + ifd
    return jpeg[:2] + b"\xff\xe1" + struct.pack(">H", len(payload) + 2) + payload + jpeg[2:]


def move_project(ctx, new_dir_name, mesh_name=None):
    """Moves the project copy into a sibling folder named `new_dir_name` (optionally renaming the
    mesh file); ctx follows."""
    new_dir = os.path.join(os.path.dirname(ctx.proj_dir), new_dir_name)
    shutil.move(ctx.proj_dir, new_dir)
    ctx.mlp = os.path.join(new_dir, os.path.basename(ctx.mlp))
    ctx.lp = os.path.join(new_dir, os.path.basename(ctx.lp))
    ctx.proj_dir = new_dir
    if mesh_name:
        old = ctx.mesh
        os.rename(old, os.path.join(new_dir, mesh_name))
        text = lib.read_text(ctx.mlp).replace(f'filename="{os.path.basename(old)}"', f'filename="{mesh_name}"')
        text = text.replace(f'label="{os.path.basename(old)}"', f'label="{mesh_name}"')
        lib.write_text(ctx.mlp, text)


def set_lp_direction(ctx, index, direction):
    entries = read_lp(ctx.lp)
    entries[index] = (entries[index][0], [str(c) for c in direction])
    write_lp(ctx.lp, entries)
    return os.path.basename(entries[index][0])


# ---------------------------------------------------------------------------------------------
# The cases. Each edit returns the strings the output must contain.

def c_missing_image(ctx):
    label, photo = ctx.rasters()[1]
    os.remove(os.path.join(ctx.proj_dir, photo))
    return [os.path.basename(photo), "missing", label, "Restore the file"]


def c_png_truncated(ctx):
    path = ctx.photo(2)
    data = open(path, "rb").read()
    open(path, "wb").write(data[: len(data) // 2])
    return [os.path.basename(path), "cannot be decoded"]


def c_png_empty(ctx):
    path = ctx.photo(2)
    open(path, "wb").close()
    return [os.path.basename(path), "cannot be decoded"]


def c_photo_wrong_size(ctx):
    path = ctx.photo(3)
    ctx.variant("half", path, path)
    return [os.path.basename(path), "320x240", "640x480", "use the photo the camera was registered with"]


def c_lp_count(ctx):
    entries = read_lp(ctx.lp)
    write_lp(ctx.lp, entries[:-1])
    return [os.path.basename(ctx.lp), "has no entry for raster", ctx.rasters()[-1][0]]


def c_lp_short(ctx):  # the count line says 16, one light line is missing
    entries = read_lp(ctx.lp)
    write_lp(ctx.lp, entries[:-1], count=len(entries))
    return [os.path.basename(ctx.lp), "says 16 lights but 15 light lines follow"]


def c_lp_name(ctx):
    entries = read_lp(ctx.lp)
    entries[0] = ("renamed_photo.png", entries[0][1])
    write_lp(ctx.lp, entries)
    return [os.path.basename(ctx.lp), "has no entry for raster", ctx.rasters()[0][0]]


def c_lp_extra(ctx):
    entries = read_lp(ctx.lp)
    write_lp(ctx.lp, entries + [("extra_photo.png", entries[0][1])])
    return [os.path.basename(ctx.lp), "extra_photo.png", "matches no raster"]


def c_no_lp(ctx):
    os.remove(ctx.lp)
    return ["No light file (.lp) found", "lightFile"]


def c_lp_nan(ctx):
    entries = read_lp(ctx.lp)
    entries[2] = (entries[2][0], ["nan", "nan", "nan"])
    write_lp(ctx.lp, entries)
    return [os.path.basename(ctx.lp), "line 4", "'nan' is not a number"]


def c_lp_zero(ctx):
    set_lp_direction(ctx, 2, [0, 0, 0])
    return [os.path.basename(ctx.lp), "line 4", "zero length"]


def c_lp_crlf(ctx):
    write_lp(ctx.lp, read_lp(ctx.lp), newline="\r\n")
    return ["16 directional lights"]


def c_lp_bom(ctx):
    write_lp(ctx.lp, read_lp(ctx.lp), bom=True)
    return ["16 directional lights"]


def c_lp_duplicate_entry(ctx):  # one photo listed twice with different directions
    entries = read_lp(ctx.lp)
    write_lp(ctx.lp, entries + [(entries[4][0], entries[9][1])])
    return [os.path.basename(ctx.lp), os.path.basename(entries[4][0]), "is listed again", "keep the one line"]


def c_lp_upper_case(ctx):  # names written in another case (an .lp made on Windows)
    entries = [(name.upper(), d) for name, d in read_lp(ctx.lp)]
    write_lp(ctx.lp, entries)
    return ["16 directional lights"]


def c_photos_differ_in_case(ctx):  # light_001.png renamed LIGHT_000.png: two names equal but for case
    label, photo = ctx.rasters()[1]
    new = os.path.join(os.path.dirname(photo), "LIGHT_000.png")
    os.rename(os.path.join(ctx.proj_dir, photo), os.path.join(ctx.proj_dir, new))
    lib.write_text(ctx.mlp, lib.read_text(ctx.mlp).replace(f'fileName="{photo}"', f'fileName="{new}"'))
    lib.write_text(ctx.lp, lib.read_text(ctx.lp).replace(photo, new))
    return ["16 directional lights"]


def c_lp_absolute(ctx):
    entries = [(os.path.join(ctx.proj_dir, name), d) for name, d in read_lp(ctx.lp)]
    write_lp(ctx.lp, entries)
    return ["16 directional lights"]


def c_lp_flipped(ctx):
    entries = read_lp(ctx.lp)
    name, d = entries[1]
    entries[1] = (name, [repr(-float(c)) for c in d])
    write_lp(ctx.lp, entries)
    return [os.path.basename(ctx.lp), "disagrees with photo", os.path.basename(name)]


def c_duplicate_lights(ctx):  # two photos under one light (the second taken twice)
    entries = read_lp(ctx.lp)
    shutil.copyfile(ctx.photo(5), ctx.photo(6))
    entries[6] = (entries[6][0], entries[5][1])
    write_lp(ctx.lp, entries)
    return ["are identical", ctx.rasters()[5][0], ctx.rasters()[6][0]]


def c_light_below_horizon(ctx):  # one light behind the object (z < 0 in the camera frame): its photo is dark
    set_lp_direction(ctx, 3, [0.3, 0.2, -0.93])
    path = ctx.photo(3)
    ctx.variant("black", path, path)
    return ["16 directional lights", "WARNING: raster '" + ctx.rasters()[3][0], "is black"]


def c_light_inside(ctx):
    ply = lib.read_ply(ctx.mesh)
    centre = [float((ply.vertex[c].min() + ply.vertex[c].max()) / 2) for c in "xyz"]
    images = [os.path.basename(photo) for _, photo in ctx.rasters()]
    positions = [centre] + [[c + 100.0 for c in centre]] * (len(images) - 1)
    path = os.path.join(ctx.proj_dir, "lights_near.json")
    lib.write_text(path, json.dumps({"images": images, "position_world": positions}))
    ctx.values["lightFile"] = path
    return ["lights_near.json", images[0], "inside the mesh's bounding box"]


def c_single_photo(ctx):
    keep_rasters(ctx, {0})
    return ["1 directional light"]


def c_no_shot(ctx):
    text = lib.read_text(ctx.mlp)
    label = ctx.rasters()[2][0]
    start = text.index(f'<MLRaster label="{label}"')
    cam = text.index("<VCGCamera", start)
    lib.write_text(ctx.mlp, text[:cam] + text[text.index("/>", cam) + 2:])
    return [label, "no valid camera", "register it"]


def c_identity_camera(ctx):  # MeshLab's camera of a raster imported but never registered
    def identity(a):
        a["TranslationVector"] = "0 0 0 1"
        a["RotationMatrix"] = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 "
    label = raster_camera(ctx, 4, identity)
    return [label, "identity camera", "not registered", "Register it"]


def c_focal_nan(ctx):
    label = raster_camera(ctx, 1, lambda a: a.update(FocalMm="nan"))
    return [label, "no valid camera"]


def c_focal_zero(ctx):
    label = raster_camera(ctx, 1, lambda a: a.update(FocalMm="0"))
    return [label, "no valid camera"]


def c_camera_sees_nothing(ctx):  # one camera turned around: it looks away from the mesh
    def turn(a):
        r = [float(x) for x in a["RotationMatrix"].split()]
        for row in (0, 2):  # right and back axes reversed: a rotation by pi about the up axis
            for k in range(3):
                r[4 * row + k] = -r[4 * row + k]
        a["RotationMatrix"] = " ".join(repr(x) for x in r) + " "
    label = raster_camera(ctx, 7, turn)
    return [f"raster '{label}' sees no vertex", "the other photos were used without it"]


def c_zero_normal(ctx):
    def zero7(v, f):
        for c in ("nx", "ny", "nz"):
            v[c][7] = 0
        return v, f
    edit_mesh(ctx.mesh, zero7)
    return ["vertex 7", "no normal", "Re-Compute Vertex Normals"]


def c_no_normals(ctx):  # normals in the file, all zero
    def zero_all(v, f):
        for c in ("nx", "ny", "nz"):
            v[c][:] = 0
        return v, f
    edit_mesh(ctx.mesh, zero_all)
    return ["Re-Compute Vertex Normals"]


def c_normals_absent(ctx):  # a file without normals: MeshLab computes them on load
    def strip(v, f):
        names = [n for n in v.dtype.names if n not in ("nx", "ny", "nz")]
        return v[names].copy(), f
    edit_mesh(ctx.mesh, strip)
    return ["has none; MeshLab computed them when loading it, from the faces (angle-weighted"]


def c_empty_mesh(ctx):
    edit_mesh(ctx.mesh, lambda v, f: (v[:0], np.zeros((0, 3), np.int64)))
    return ["has no vertices"]


def c_degenerate_faces(ctx):  # faces with a repeated vertex and zero-area slivers added
    def add(v, f):
        extra = np.array([[0, 0, 1], [5, 5, 5], [2, 3, 2]], dtype=f.dtype)
        return v, np.concatenate([f, extra])
    edit_mesh(ctx.mesh, add)
    return ["normals: the per-vertex normals the mesh file stores"]


def c_duplicate_faces(ctx):  # every face twice
    edit_mesh(ctx.mesh, lambda v, f: (v, np.concatenate([f, f])))
    return ["normals: the per-vertex normals the mesh file stores"]


def c_mesh_missing(ctx):
    name = os.path.basename(ctx.mesh)
    os.remove(ctx.mesh)
    return [name]


def c_photo_variant(mode, ext, expect=()):
    def edit(ctx):
        convert_photos(ctx, mode, ext)
        return list(expect)
    return edit


def c_exif_rotated(ctx):  # JPEGs tagged "rotate 90" (EXIF orientation 6), pixels stored landscape
    convert_photos(ctx, "jpeg", "jpg")
    for _, photo in ctx.rasters():
        path = os.path.join(ctx.proj_dir, photo)
        data = open(path, "rb").read()
        open(path, "wb").write(add_exif_orientation(data, 6))
    return ["16 directional lights"]


def c_photo_over_budget(ctx):  # photos of 3200x2400 (22 MB decoded) with 'Photo memory (MB)' 16
    # TIFF: a format the fit decodes itself (host_photos.h; PNG and JPEG are read in place from
    # MeshLab's images and take none of the budget), so the budget's streaming path runs.
    convert_photos(ctx, "big", "tif")
    text = lib.read_text(ctx.mlp)
    text = text.replace('ViewportPx="640 480"', 'ViewportPx="3200 2400"').replace('CenterPx="320 240"', 'CenterPx="1600 1200"')
    text = re.sub(r'PixelSizeMm="([\d.e-]+) ([\d.e-]+)"',
                  lambda m: f'PixelSizeMm="{float(m.group(1)) / 5!r} {float(m.group(2)) / 5!r}"', text)
    lib.write_text(ctx.mlp, text)
    ctx.values["memoryBudgetMB"] = 16
    return ["more than 'Photo memory (MB)' (16 MB)", "decoded again for each vertex chunk"]


def c_memory_budget_tiny(ctx):
    ctx.values["memoryBudgetMB"] = 1
    return ["memoryBudgetMB", "Photo memory (MB)", "at least 16"]


def c_all_photos(mode):
    def edit(ctx):
        paths = [os.path.join(ctx.proj_dir, photo) for _, photo in ctx.rasters()]
        ctx.variants(mode, [(p, p) for p in paths])
        word = {"black": "Every photo is black", "white": "Every photo is saturated"}[mode]
        return [word, os.path.basename(ctx.rasters()[0][1]), "Re-shoot", "Nothing was written"]
    return edit


def c_one_black(ctx):
    path = ctx.photo(9)
    ctx.variant("black", path, path)
    return ["WARNING: raster '" + ctx.rasters()[9][0], "is black"]


def c_all_identical(ctx):
    first = ctx.photo(0)
    for i in range(1, len(ctx.rasters())):
        shutil.copyfile(first, ctx.photo(i))
    return ["photos are identical", ctx.rasters()[0][0], "its own light", "Nothing was written"]


def c_path_spaces(ctx):
    move_project(ctx, "my project (copy) 2", mesh_name="scan with spaces.ply")
    return ["16 directional lights"]


def c_path_non_ascii(ctx):
    move_project(ctx, "projet_été_Ωmega", mesh_name="maillage_ü.ply")
    return ["16 directional lights"]


def c_param_out_of_range(ctx):
    ctx.values["specularThreshold"] = 1.5
    return ["specularThreshold"]


def c_outdir_missing(ctx):
    ctx.values["outputPly"] = os.path.join(ctx.out_dir, "no_such_folder", "result.ply")
    return ["no_such_folder", "does not exist", "Output PLY"]


def c_overwrite_refused(ctx):  # an earlier result present, 'Overwrite existing output' off
    path = os.path.join(ctx.out_dir, "result.ply")
    ctx.pre_existing["result.ply"] = b"ply\nan earlier result\n"
    ctx.values["overwriteOutput"] = "false"
    return ["result.ply", "already exists", "Overwrite existing output", "Nothing was written"]


def c_overwrite_default(ctx):  # an earlier result present, the default: replaced, and said so
    ctx.pre_existing["result.ply"] = b"ply\nan earlier result\n"
    return ["replaces the existing file (22 bytes)"]


def c_gl(version, values, expect):
    """Mesa's software renderer made to report an older OpenGL (MESA_GL_VERSION_OVERRIDE)."""
    def edit(ctx):
        ctx.env["MESA_GL_VERSION_OVERRIDE"] = version
        ctx.values.update(values)
        return list(expect)
    return edit


CASES = [
    # Photos
    Case("missing_image", "photo", "fail", "a raster's photo file is missing", c_missing_image),
    Case("png_truncated", "photo", "fail", "a PNG cut in half", c_png_truncated),
    Case("png_empty", "photo", "fail", "a zero-byte PNG", c_png_empty),
    Case("photo_wrong_size", "photo", "fail", "a photo of another size than its camera", c_photo_wrong_size),
    Case("photo_jpeg", "photo", "sane", "every photo a JPEG", c_photo_variant("jpeg", "jpg")),
    Case("photo_tiff16", "photo", "sane", "16-bit linear TIFFs (taken as linear)", c_photo_variant("tiff16", "tif")),
    Case("photo_grey8", "photo", "sane", "1-channel 8-bit PNGs", c_photo_variant("grey8", "png")),
    Case("photo_grey16", "photo", "sane", "1-channel 16-bit linear PNGs", c_photo_variant("grey16", "png")),
    Case("photo_rgba", "photo", "sane", "RGBA PNGs (alpha ignored)", c_photo_variant("rgba", "png")),
    Case("photo_cmyk_jpeg", "photo", "sane", "Adobe CMYK JPEGs", c_photo_variant("cmyk_jpeg", "jpg")),
    Case("photo_exif_rotated", "photo", "sane",
         "JPEGs with EXIF orientation 6: ignored, as MeshLab's loader (Qt 5) ignores it", c_exif_rotated),
    Case("photo_over_budget", "photo", "sane", "3200x2400 TIFF photos (decoded by the fit), each larger than 'Photo memory (MB)' = 16",
         c_photo_over_budget),
    Case("memory_budget_tiny", "photo", "fail", "'Photo memory (MB)' = 1", c_memory_budget_tiny),
    # Photo content
    Case("all_black", "content", "fail", "every photo black", c_all_photos("black")),
    Case("all_saturated", "content", "fail", "every photo saturated (all white)", c_all_photos("white")),
    Case("all_identical", "content", "fail", "every photo the same file", c_all_identical),
    Case("one_black", "content", "sane", "one photo black among 16", c_one_black),
    Case("duplicate_lights", "content", "sane", "two photos with one light, the second a copy of the first",
         c_duplicate_lights),
    # Light file
    Case("no_lp", "lights", "fail", "no light file anywhere", c_no_lp),
    Case("lp_count", "lights", "fail", "an .lp one entry short (count consistent)", c_lp_count),
    Case("lp_short", "lights", "fail", "an .lp whose count says one line more than it has", c_lp_short),
    Case("lp_name", "lights", "fail", "an entry naming no photo of the project", c_lp_name),
    Case("lp_extra", "lights", "fail", "an entry more than there are rasters", c_lp_extra),
    Case("lp_nan", "lights", "fail", "a NaN light direction", c_lp_nan),
    Case("lp_zero", "lights", "fail", "a zero-length light direction", c_lp_zero),
    Case("lp_duplicate_entry", "lights", "fail", "one photo listed twice with different directions",
         c_lp_duplicate_entry),
    Case("lp_crlf", "lights", "sane", "an .lp with CRLF line ends", c_lp_crlf),
    Case("lp_bom", "lights", "sane", "an .lp starting with a UTF-8 byte-order mark", c_lp_bom),
    Case("lp_upper_case", "lights", "sane", "photo names in the .lp in upper case", c_lp_upper_case),
    Case("photos_differ_in_case", "lights", "sane", "two photo names equal but for case (light_000, LIGHT_000)",
         c_photos_differ_in_case),
    Case("lp_absolute", "lights", "sane", "absolute photo paths in the .lp", c_lp_absolute),
    Case("lp_flipped", "lights", "fail", "one light direction reversed (contradicts its photo)", c_lp_flipped),
    Case("light_inside", "lights", "fail", "a light position inside the object (.json)", c_light_inside),
    Case("light_below_horizon", "lights", "sane", "a light behind the object (z < 0), its photo dark: warned",
         c_light_below_horizon),
    Case("single_photo", "lights", "sane", "a project with one photo", c_single_photo, min_coloured=0.2),
    # Cameras
    Case("no_shot", "camera", "fail", "a raster without <VCGCamera>", c_no_shot),
    Case("identity_camera", "camera", "fail", "a raster with MeshLab's identity camera (never registered)",
         c_identity_camera),
    Case("focal_nan", "camera", "fail", "a NaN focal length", c_focal_nan),
    Case("focal_zero", "camera", "fail", "a zero focal length", c_focal_zero),
    Case("camera_sees_nothing", "camera", "sane", "one camera looking away from the mesh", c_camera_sees_nothing),
    # Mesh
    Case("mesh_missing", "mesh", "fail", "the project's mesh file is missing", c_mesh_missing, in_filter=False),
    Case("empty_mesh", "mesh", "fail", "a mesh with zero vertices", c_empty_mesh),
    Case("zero_normal", "mesh", "fail", "one vertex with a zero normal", c_zero_normal),
    Case("no_normals", "mesh", "fail", "normals in the file, all zero", c_no_normals),
    Case("normals_absent", "mesh", "sane", "a mesh file without normals (MeshLab computes them on load)",
         c_normals_absent),
    Case("degenerate_faces", "mesh", "sane", "faces with a repeated vertex added", c_degenerate_faces),
    Case("duplicate_faces", "mesh", "sane", "every face twice", c_duplicate_faces),
    # Paths and parameters
    Case("path_spaces", "paths", "sane", "spaces and brackets in the folder and mesh names", c_path_spaces),
    Case("path_non_ascii", "paths", "sane", "non-ASCII folder and mesh names", c_path_non_ascii),
    Case("param_out_of_range", "paths", "fail", "'Specular threshold' 1.5", c_param_out_of_range),
    Case("outdir_missing", "paths", "fail", "'Output PLY' in a folder that does not exist", c_outdir_missing),
    Case("overwrite_refused", "output", "fail", "an earlier result, 'Overwrite existing output' off",
         c_overwrite_refused),
    Case("overwrite_default", "output", "sane", "an earlier result, the default: replaced and logged",
         c_overwrite_default),
    # OpenGL (Mesa reporting an older version: no compute shaders, or not even the depth passes)
    Case("gl_no_compute", "gl", "sane", "GL 3.3, no compute shaders, 'Fit back end' Auto: the CPU fit, logged",
         c_gl("3.3COMPAT", {}, ["GPU back end unavailable", "needs OpenGL 4.3 compute shaders", "using the CPU reference"])),
    Case("gl_no_compute_forced", "gl", "fail", "GL 3.3 with 'Fit back end' GPU: refused, naming the parameter",
         c_gl("3.3COMPAT", {"fitBackend": 1}, ["'Fit back end' is set to GPU", "needs OpenGL 4.3", "Set 'Fit back end' to Auto or CPU"])),
    Case("gl_too_old", "gl", "sane", "GL 3.0: no depth passes either, CPU ray caster and CPU fit, logged",
         c_gl("3.0", {}, ["GL depth passes unavailable", "using the CPU ray caster", "using the CPU reference"])),
    Case("gl_too_old_forced", "gl", "fail", "GL 3.0 with 'Visibility' GPU: refused, naming the parameter",
         c_gl("3.0", {"visibilityBackend": 1}, ["'Visibility' is set to GPU (OpenGL)", "Set 'Visibility' to Auto or CPU"])),
]

BY_NAME = {c.name: c for c in CASES}
