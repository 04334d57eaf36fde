#!/usr/bin/python3
"""Builds a registered MeshLab project from one object of the classic photometric-stereo set
(Seitz, UW CSE 455 "psmImages": 12 photos, 512x340 uncompressed TGA, a mask, chrome-sphere
light directions in lights.txt), so that the plugin can fit it and vbrdf_eval can score it.

    make_psm_project.py DATA_DIR OBJECT OUT_DIR [--heldout I J K] [--photos linear|srgb]
                        [--camera-distance D]

DATA_DIR holds lights.txt and OBJECT/OBJECT.{0..11}.tga + OBJECT.mask.tga (e.g.
../shared/real/psm_uw_seitz), or it is the Harvard set (Xiong et al., e.g.
../shared/real/harvard_psdata): OBJECT/Objects/Image_01..20.png (8-bit grey), the light directions
OBJECT/light_directions.txt (3 rows of n: x, y, z in the .lp's camera frame, as the repository's
lights tool test checks against the set's mirror spheres) and the mask
third_party_masks_hjl18/OBJECT_mask.png. Which one is told by lights.txt in DATA_DIR. Written to
OUT_DIR:
    mesh.ply          binary PLY: one vertex per mask pixel (x y z nx ny nz), in the order of
                      the mask's pixels (row-major), then a skirt: one vertex per pixel of the
                      ring just outside the mask, moved half a pixel towards it, so that the
                      relief covers every mask pixel whole as the object does in the photos; two
                      triangles per 2x2 block; normals = the photometric-stereo normals (the
                      skirt's: its mask neighbours' mean)
    object_pixels.ply the same mesh with a uchar `visible`: 1 for the mask pixels' vertices, 0 for
                      the skirt (vbrdf_eval --gt-visible scores the object's pixels only)
    project.mlp       the mesh + one raster per training photo, all with the same camera
    lights.lp         count, then `images/light_KK.png lx ly lz` (camera frame: x right, y up,
                      z towards the viewer; unit directions towards the light)
    images/           the training photos as RGB PNG (16-bit linear or 8-bit as given: --photos)
    heldout/          project.mlp (mesh ../mesh.ply), lights.lp, images/ for the held-out lights
    psm_project.json  what was done (light indices, sample counts, depth range, registration)

Method (python3 + numpy only):
  * Photo encoding (--photos). `linear` (default): the 8-bit values are proportional to
    radiance; the photos are written as 16-bit PNG (value * 257, exact), which the plugin's
    default (photo encoding Auto) reads as linear. `srgb`: the 8-bit values are taken as
    sRGB-encoded and written as 8-bit PNG as given (Auto decodes 8-bit as sRGB). Either way the
    photometric stereo uses the same linear values the plugin will see; grey = mean of RGB.
    Why linear by default: on the set's matte grey sphere (gray/, normals known from the mask's
    circle) the 8-bit grey follows (N.L)^0.92 as given but (N.L)^1.93 after sRGB decoding
    (grey_sphere_exponent() below), and the course's reference buddha normals
    (extras_reference_outputs) agree with normals from the values as given (median 1.8 deg)
    but not from sRGB-decoded ones (16.5 deg). Decoding as sRGB tilts every normal away from
    the camera, so about half of all vertex-photo pairs fall under T_d = 0.5 on N.L.
  * Normals: per-pixel least squares I = L g (g = albedo * n) on the training lights only. A
    sample is dropped when it is saturated (any channel >= 250 of 255) or dark (grey below
    DARK_FRACTION of the pixel's brightest unsaturated training sample, or below DARK_ABS),
    as long as at least MIN_SAMPLES remain; otherwise all unsaturated samples are used (all
    samples when fewer than 3 are unsaturated). Pixels whose system is degenerate get (0,0,1).
  * Depth: least-squares Poisson integration of the gradients (p, q) = (-nx/nz, -ny/nz) over the
    mask, using only the finite differences between neighbouring mask pixels (so mask borders
    need no boundary condition), by conjugate gradients on the normal equations with a tiny
    pull towards 0 that fixes each connected component's constant. Slopes are clipped at
    MAX_SLOPE (about 80 degrees) for the integration only. Depth is in pixel units, +z towards
    the camera.
  * Camera: identity rotation, centre (0, 0, D) with D = --camera-distance (default 1e5 px, far
    compared with any relief, so the view is nearly orthographic as lights.txt assumes),
    f = D px at depth 0 (FocalMm = D * PixelSizeMm), CenterPx = (W/2, H/2). Each vertex's x, y
    is set from its pixel centre and depth so that MeshLab's projection (the "Conventions" of the
    shared scenes' own README: cp = R (p - C), cp.z = -cp.z, px = f cp.xy / cp.z / PixelSizeMm + CenterPx,
    VCG pixels with y up, origin bottom-left) lands exactly on it: pixel (col c, top-down row r)
    -> VCG (c + 0.5, H - r - 0.5). The tool re-projects every vertex (float32 as written, camera
    parsed back from the written .mlp) and fails when any lands more than 0.01 px off.

Light frame: lights.txt is x right, y up in the image, z towards the camera (SOURCES.md,
checked against the chrome sphere), which is the camera frame of the .lp files; with the
identity camera rotation it is also the world frame, so the directions are written unchanged.

Held-out lights (default): 3 lights chosen so that the held-out lights interpolate the training
set and spread over it: only lights whose (x, y) lies strictly inside the convex hull of the
lights that stay for training are candidates; the first is the candidate farthest from the mean
light direction, each next one the candidate farthest from those already chosen (ties: lower
index). For the Seitz lights this gives 6, 11, 1 (right, left, bottom of the light set).

Exit status: 0 success, 2 bad input, 3 registration check failed.
"""
import argparse
import json
import os
import struct
import sys
import zlib

import numpy as np

SATURATED = 250       # 8-bit value at or above which a channel counts as clipped
DARK_FRACTION = 0.1   # a sample darker than this fraction of the pixel's brightest is shadowed
DARK_ABS = 0.004      # linear grey below this counts as dark in any case
MIN_SAMPLES = 4       # keep dropping dark/saturated samples only while this many remain
MAX_SLOPE = 6.0       # |dz/dx| clip for the integration (about 80 degrees)
MIN_NZ = 0.05         # smallest N.E of a photometric-stereo normal (about 87 degrees from the view)
PIXEL_SIZE_MM = 0.01
REGISTRATION_TOL_PX = 0.01


class InputError(Exception):
    pass


# ----------------------------------------------------------------------------- file reading
def read_tga(path):
    """Uncompressed true-colour TGA (type 2, 24 or 32 bit) -> uint8 array (H, W, 3), top row
    first. Honours the origin bit (bit 5 of the descriptor: set = top-left origin)."""
    with open(path, 'rb') as f:
        data = f.read()
    if len(data) < 18:
        raise InputError('%s: not a TGA file' % path)
    id_len, cmap_type, img_type = data[0], data[1], data[2]
    cmap_len = struct.unpack_from('<H', data, 5)[0]
    cmap_bits = data[7]
    width, height = struct.unpack_from('<HH', data, 12)
    bpp, desc = data[16], data[17]
    if img_type != 2 or bpp not in (24, 32):
        raise InputError('%s: only uncompressed 24/32-bit TGA is supported (type %d, %d bpp)'
                         % (path, img_type, bpp))
    offset = 18 + id_len + (cmap_len * ((cmap_bits + 7) // 8) if cmap_type else 0)
    n = width * height * (bpp // 8)
    if len(data) < offset + n:
        raise InputError('%s: truncated' % path)
    pix = np.frombuffer(data, np.uint8, n, offset).reshape(height, width, bpp // 8)
    rgb = pix[:, :, 2::-1]  # BGR(A) -> RGB
    if desc & 0x10:
        rgb = rgb[:, ::-1]
    if not desc & 0x20:     # bottom-left origin: first stored row is the bottom one
        rgb = rgb[::-1]
    return np.ascontiguousarray(rgb)


def read_png(path):
    """8/16-bit grey, grey+alpha, RGB or RGBA PNG (non-interlaced) -> uint8/uint16 array (H, W, C),
    with the standard library's zlib and numpy only (unfiltering: Sub and Up vectorised, Average
    and Paeth per pixel)."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise InputError('%s: not a PNG file' % path)
    pos, idat, header = 8, [], None
    while pos + 8 <= len(data):
        length, kind = struct.unpack_from('>I4s', data, pos)
        body = data[pos + 8:pos + 8 + length]
        if kind == b'IHDR':
            header = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat.append(body)
        elif kind == b'IEND':
            break
        pos += 12 + length
    if header is None:
        raise InputError('%s: no IHDR' % path)
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if channels is None or depth not in (8, 16) or interlace:
        raise InputError('%s: only non-interlaced 8/16-bit grey or RGB(A) PNG is supported' % path)
    bpp = channels * depth // 8
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(b''.join(idat)), np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), np.uint8)
    prior = np.zeros(stride, np.int32)
    for r in range(height):
        kind, line = raw[r, 0], raw[r, 1:].astype(np.int32)
        if kind == 0:
            rec = line
        elif kind == 1:
            rec = np.cumsum(line.reshape(width, bpp), axis=0).reshape(stride) % 256
        elif kind == 2:
            rec = (line + prior) % 256
        elif kind in (3, 4):
            rec = np.zeros(stride, np.int32)
            for i in range(0, stride, bpp):
                left = rec[i - bpp:i] if i else np.zeros(bpp, np.int32)
                up = prior[i:i + bpp]
                if kind == 3:
                    pred = (left + up) // 2
                else:
                    upleft = prior[i - bpp:i] if i else np.zeros(bpp, np.int32)
                    p = left + up - upleft
                    pa, pb, pc = np.abs(p - left), np.abs(p - up), np.abs(p - upleft)
                    pred = np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, up, upleft))
                rec[i:i + bpp] = (line[i:i + bpp] + pred) % 256
        else:
            raise InputError('%s: unknown PNG filter %d' % (path, kind))
        out[r] = rec
        prior = rec
    if depth == 16:
        return (out.reshape(height, width * channels, 2).astype(np.uint16) * np.array([256, 1], np.uint16)).sum(
            axis=2, dtype=np.uint16).reshape(height, width, channels)
    return out.reshape(height, width, channels)


def load_seitz(data_dir, name):
    """Photos (H, W, 3) uint8, mask (H, W) bool and unit light directions (n, 3) of a Seitz object."""
    lights = read_lights(os.path.join(data_dir, 'lights.txt'))
    obj_dir = os.path.join(data_dir, name)
    if not os.path.isdir(obj_dir):
        raise InputError('%s: no such object folder' % obj_dir)
    photos = [read_tga(os.path.join(obj_dir, '%s.%d.tga' % (name, k))) for k in range(len(lights))]
    mask_img = read_tga(os.path.join(obj_dir, '%s.mask.tga' % name))
    if mask_img.shape != photos[0].shape:
        raise InputError('%s: photos and mask differ in size' % obj_dir)
    return photos, mask_img.max(axis=2) > 127, lights


def load_harvard(data_dir, name):
    """The same for an object of the Harvard set (grey photos replicated to RGB)."""
    obj_dir = os.path.join(data_dir, name)
    path = os.path.join(obj_dir, 'light_directions.txt')
    if not os.path.isfile(path):
        raise InputError('%s: no such file (Harvard object folder expected)' % path)
    with open(path) as f:
        values = np.array([float(t) for t in f.read().split()])
    if values.size % 3 or values.size == 0:
        raise InputError('%s: expected 3 rows of n directions' % path)
    lights = values.reshape(3, -1).T
    lights = lights / np.linalg.norm(lights, axis=1)[:, None]
    photos = []
    for k in range(len(lights)):
        img = read_png(os.path.join(obj_dir, 'Objects', 'Image_%02d.png' % (k + 1)))
        if img.dtype != np.uint8:
            raise InputError('%s: 8-bit photos expected' % obj_dir)
        photos.append(np.ascontiguousarray(np.repeat(img[:, :, :1], 3, axis=2) if img.shape[2] < 3 else img[:, :, :3]))
    mask_img = read_png(os.path.join(data_dir, 'third_party_masks_hjl18', '%s_mask.png' % name))
    if mask_img.shape[:2] != photos[0].shape[:2]:
        raise InputError('%s: photos and mask differ in size' % obj_dir)
    return photos, mask_img[:, :, 0] > 127, lights


def read_lights(path):
    with open(path) as f:
        tokens = f.read().split()
    try:
        count = int(tokens[0])
        values = np.array([float(t) for t in tokens[1:1 + 3 * count]]).reshape(count, 3)
    except (ValueError, IndexError):
        raise InputError('%s: expected a count then count lines of x y z' % path)
    norms = np.linalg.norm(values, axis=1)
    if np.any(norms < 1e-6):
        raise InputError('%s: zero light direction' % path)
    return values / norms[:, None]


# ----------------------------------------------------------------------------- file writing
def write_png(path, rgb):
    """RGB PNG, 8-bit for uint8 input, 16-bit for uint16 (no filtering, zlib level 6)."""
    h, w, _ = rgb.shape
    depth = 16 if rgb.dtype == np.uint16 else 8
    row = rgb.astype('>u2' if depth == 16 else np.uint8).reshape(h, -1).view(np.uint8)
    raw = np.zeros((h, 1 + row.shape[1]), np.uint8)
    raw[:, 1:] = row

    def chunk(tag, payload):
        return (struct.pack('>I', len(payload)) + tag + payload
                + struct.pack('>I', zlib.crc32(tag + payload) & 0xffffffff))
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n')
        f.write(chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, depth, 2, 0, 0, 0)))
        f.write(chunk(b'IDAT', zlib.compress(raw.tobytes(), 6)))
        f.write(chunk(b'IEND', b''))


def write_ply(path, positions, normals, faces, visible=None):
    fields = [('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('nx', '<f4'), ('ny', '<f4'), ('nz', '<f4')]
    if visible is not None:
        fields.append(('visible', 'u1'))
    vert = np.zeros(len(positions), dtype=fields)
    for i, name in enumerate('xyz'):
        vert[name] = positions[:, i]
        vert['n' + name] = normals[:, i]
    if visible is not None:
        vert['visible'] = visible
    face = np.zeros(len(faces), dtype=[('n', 'u1'), ('v', '<i4', (3,))])
    face['n'] = 3
    face['v'] = faces
    header = ('ply\nformat binary_little_endian 1.0\ncomment generated by make_psm_project.py\n'
              'element vertex %d\nproperty float x\nproperty float y\nproperty float z\n'
              'property float nx\nproperty float ny\nproperty float nz\n%s'
              'element face %d\nproperty list uchar int vertex_indices\nend_header\n'
              % (len(vert), 'property uchar visible\n' if visible is not None else '', len(face)))
    with open(path, 'wb') as f:
        f.write(header.encode('ascii'))
        f.write(vert.tobytes())
        f.write(face.tobytes())
    return vert


def camera_attributes(width, height, distance):
    """VCGCamera attributes of the far camera (see the module docstring)."""
    return {
        'TranslationVector': '0 0 %.10g 1' % -distance,
        'LensDistortion': '0 0',
        'ViewportPx': '%d %d' % (width, height),
        'PixelSizeMm': '%.10g %.10g' % (PIXEL_SIZE_MM, PIXEL_SIZE_MM),
        'CenterPx': '%.10g %.10g' % (width / 2.0, height / 2.0),
        'FocalMm': '%.10g' % (distance * PIXEL_SIZE_MM),
        'RotationMatrix': '1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ',
        'CameraType': '0',
        'BinaryData': '0',
    }


def write_mlp(path, mesh_file, image_files, camera):
    attrs = ' '.join('%s="%s"' % (k, v) for k, v in camera.items())
    lines = ['<!DOCTYPE MeshLabDocument>', '<MeshLabProject>', ' <MeshGroup>',
             '  <MLMesh label="mesh.ply" filename="%s" visible="1">' % mesh_file,
             '   <MLMatrix44>', '1 0 0 0 ', '0 1 0 0 ', '0 0 1 0 ', '0 0 0 1 ', '</MLMatrix44>',
             '  </MLMesh>', ' </MeshGroup>', ' <RasterGroup>']
    for image in image_files:
        lines += ['  <MLRaster label="%s">' % os.path.basename(image),
                  '   <VCGCamera %s/>' % attrs,
                  '   <Plane semantic="1" fileName="%s"/>' % image,
                  '  </MLRaster>']
    lines += [' </RasterGroup>', '</MeshLabProject>', '']
    with open(path, 'w') as f:
        f.write('\n'.join(lines))


def write_lp(path, image_files, directions):
    with open(path, 'w') as f:
        f.write('%d\n' % len(image_files))
        for image, d in zip(image_files, directions):
            f.write('%s %.6f %.6f %.6f\n' % (image, d[0], d[1], d[2]))


# ----------------------------------------------------------------------------- held-out choice
def _inside_hull(point, points):
    """True when `point` lies strictly inside the convex hull of the 2-D `points`."""
    pts = sorted(set(map(tuple, np.round(points, 12))))
    if len(pts) < 3:
        return False

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]  # counter-clockwise
    return all(cross(hull[i], hull[(i + 1) % len(hull)], point) > 1e-9 for i in range(len(hull)))


def default_heldout(lights, count=3):
    """Deterministic held-out lights (module docstring): interior lights, farthest-point order."""
    xy = lights[:, :2]
    chosen = []
    for _ in range(count):
        best, best_score = None, -1.0
        for c in range(len(lights)):
            if c in chosen:
                continue
            keep = [i for i in range(len(lights)) if i != c and i not in chosen]
            if not _inside_hull(xy[c], xy[keep]):
                continue
            if chosen:
                score = min(np.linalg.norm(xy[c] - xy[k]) for k in chosen)
            else:
                score = np.linalg.norm(xy[c] - xy.mean(axis=0))
            if score > best_score + 1e-12:
                best, best_score = c, score
        if best is None:
            raise InputError('cannot choose %d interior held-out lights; pass --heldout' % count)
        chosen.append(best)
    return chosen


# ----------------------------------------------------------------------------- reconstruction
def srgb_to_linear(u8):
    c = u8.astype(np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def photometric_normals(grey, saturated, lights):
    """grey (K, N) linear, saturated (K, N) bool, lights (K, 3) -> normals (N, 3), albedo (N,),
    used sample counts (N,). Degenerate pixels get (0, 0, 1) and albedo 0."""
    k, n = grey.shape
    unsat = ~saturated
    ref = np.where(unsat, grey, 0).max(axis=0)
    clean = unsat & (grey > np.maximum(DARK_FRACTION * ref, DARK_ABS)[None, :])
    use = np.where((clean.sum(axis=0) >= MIN_SAMPLES)[None, :], clean,
                   np.where((unsat.sum(axis=0) >= 3)[None, :], unsat, True))
    w = use.astype(np.float64)
    a = np.einsum('kn,ki,kj->nij', w, lights, lights)
    b = np.einsum('kn,kn,ki->ni', w, grey, lights)
    det = np.linalg.det(a)
    ok = det > 1e-9
    g = np.zeros((n, 3))
    g[ok] = np.linalg.solve(a[ok], b[ok][:, :, None])[:, :, 0]
    albedo = np.linalg.norm(g, axis=1)
    ok &= albedo > 1e-9
    normals = np.tile(np.array([0.0, 0.0, 1.0]), (n, 1))
    normals[ok] = g[ok] / albedo[ok, None]
    # A surface the camera sees faces it: N.E >= MIN_NZ (the camera looks along -z). Noise can tilt a
    # rim pixel's normal past 90 degrees; nz = 0 would make the vertex edge-on, and the fit would
    # count it as seen by no photo (owl: 12 vertices).
    low = normals[:, 2] < MIN_NZ
    tangential = np.linalg.norm(normals[low, :2], axis=1, keepdims=True).clip(1e-12)
    normals[low, :2] *= np.sqrt(1.0 - MIN_NZ ** 2) / tangential
    normals[low, 2] = MIN_NZ
    normals /= np.linalg.norm(normals, axis=1, keepdims=True).clip(1e-12)
    normals[np.linalg.norm(normals, axis=1) < 0.5] = (0.0, 0.0, 1.0)
    return normals, np.where(ok, albedo, 0.0), use.sum(axis=0)


def integrate_depth(mask, normals_img, iterations=4000, tol=1e-7):
    """Least-squares depth z (pixel units, +z towards the camera) over `mask` from normals
    (H, W, 3; camera frame, y up). Uses forward differences between 4-neighbour mask pixels:
    z[r, c+1] - z[r, c] = (p[r,c] + p[r,c+1]) / 2 and z[r+1, c] - z[r, c] = -(q[r,c] + q[r+1,c]) / 2
    (rows go down, y up). Conjugate gradients on the normal equations, plus eps * z^2 to fix the
    constant of each connected component. Returns z (H, W), 0 outside the mask."""
    h, w = mask.shape
    idx = -np.ones((h, w), np.int64)
    n = int(mask.sum())
    idx[mask] = np.arange(n)
    nz = np.maximum(normals_img[:, :, 2], 1e-3)
    p = np.clip(-normals_img[:, :, 0] / nz, -MAX_SLOPE, MAX_SLOPE)
    q = np.clip(-normals_img[:, :, 1] / nz, -MAX_SLOPE, MAX_SLOPE)
    hx = mask[:, :-1] & mask[:, 1:]
    hy = mask[:-1, :] & mask[1:, :]
    e0 = np.concatenate([idx[:, :-1][hx], idx[:-1, :][hy]])
    e1 = np.concatenate([idx[:, 1:][hx], idx[1:, :][hy]])
    rhs_e = np.concatenate([0.5 * (p[:, :-1] + p[:, 1:])[hx], -0.5 * (q[:-1, :] + q[1:, :])[hy]])
    eps = 1e-6
    degree = np.bincount(e0, minlength=n) + np.bincount(e1, minlength=n) + eps

    def apply(z):  # (D^T D + eps) z
        d = z[e1] - z[e0]
        return np.bincount(e1, d, n) - np.bincount(e0, d, n) + eps * z

    b = np.bincount(e1, rhs_e, n) - np.bincount(e0, rhs_e, n)
    z = np.zeros(n)
    r = b - apply(z)
    y = r / degree
    d = y.copy()
    ry = r @ y
    bnorm = np.linalg.norm(b) + 1e-30
    for it in range(iterations):
        ad = apply(d)
        alpha = ry / (d @ ad)
        z += alpha * d
        r -= alpha * ad
        if np.linalg.norm(r) < tol * bnorm:
            break
        y = r / degree
        ry_new = r @ y
        d = y + (ry_new / ry) * d
        ry = ry_new
    out = np.zeros((h, w))
    out[mask] = z
    residual = float(np.sqrt(np.mean((z[e1] - z[e0] - rhs_e) ** 2))) if len(e0) else 0.0
    return out, it + 1, residual


def relief_faces(mask, idx):
    """Two counter-clockwise (seen from +z, y up) triangles per 2x2 block of mask pixels."""
    full = mask[:-1, :-1] & mask[:-1, 1:] & mask[1:, :-1] & mask[1:, 1:]
    tl, tr = idx[:-1, :-1][full], idx[:-1, 1:][full]
    bl, br = idx[1:, :-1][full], idx[1:, 1:][full]
    # Image rows go down and y up: top-left -> bottom-left -> bottom-right is counter-clockwise.
    return np.concatenate([np.stack([tl, bl, br], 1), np.stack([tl, br, tr], 1)])


def skirt(mask, depth_img, normals_img):
    """The pixels just outside the mask (its 8-neighbourhood ring), as vertices moved half a pixel
    towards the mask: with them the relief covers every mask pixel whole, as the object covers it
    in the photos (a mesh ending at the boundary pixels' centres covers a quarter to a half of
    those pixels, and the camera-faithful prediction then darkens them by as much). Returns
    rows, cols (the ring pixels), shifts (K, 2: row, col offsets of +-0.5 or 0), depth and normals
    (the mean of their mask neighbours')."""
    height, width = mask.shape
    offsets = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    padded = np.pad(mask, 1)
    dilated = mask.copy()
    for dr, dc in offsets:
        dilated |= padded[1 + dr:1 + dr + height, 1 + dc:1 + dc + width]
    rows, cols = np.nonzero(dilated & ~mask)
    n = np.zeros(len(rows))
    lowest = np.full((len(rows), 2), 2)
    highest = np.full((len(rows), 2), -2)
    depth = np.zeros(len(rows))
    normal = np.zeros((len(rows), 3))
    for dr, dc in offsets:
        r, c = rows + dr, cols + dc
        ok = (r >= 0) & (r < height) & (c >= 0) & (c < width)
        ok[ok] = mask[r[ok], c[ok]]
        n += ok
        lowest[ok] = np.minimum(lowest[ok], (dr, dc))
        highest[ok] = np.maximum(highest[ok], (dr, dc))
        depth[ok] += depth_img[r[ok], c[ok]]
        normal[ok] += normals_img[r[ok], c[ok]]
    # Half a pixel along an axis only where every mask neighbour lies on the same side along it:
    # a straight edge moves across it, a corner onto the mask's corner, a pixel beside the end of
    # an edge stays in line with it.
    same_side = np.sign(lowest) == np.sign(highest)
    shifts = np.where(same_side, 0.5 * np.sign(lowest), 0.0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True).clip(1e-12)
    return rows, cols, shifts, depth / n, normal, dilated


# ----------------------------------------------------------------------------- registration
def parse_camera(mlp_path):
    """First VCGCamera of a written .mlp -> dict of float arrays."""
    import xml.etree.ElementTree as ET
    with open(mlp_path) as f:
        text = f.read()
    root = ET.fromstring(text[text.index('<MeshLabProject'):])
    cam = root.find('.//VCGCamera')
    return {k: np.array([float(t) for t in cam.get(k).split()]) for k in
            ('TranslationVector', 'ViewportPx', 'PixelSizeMm', 'CenterPx', 'FocalMm', 'RotationMatrix')}


def check_registration(mlp_path, vertices, pixel_cols, pixel_rows, height):
    """Projects every vertex (float32 as written) with the camera read back from `mlp_path`,
    MeshLab's formula, and returns the largest distance (px) to its pixel centre."""
    cam = parse_camera(mlp_path)
    rot = cam['RotationMatrix'].reshape(4, 4)[:3, :3]
    centre = -cam['TranslationVector'][:3]
    pos = np.stack([vertices['x'], vertices['y'], vertices['z']], 1).astype(np.float64)
    cp = (pos - centre) @ rot.T
    cp[:, 2] = -cp[:, 2]
    if np.any(cp[:, 2] <= 0):
        return float('inf')
    f = cam['FocalMm'][0]
    px = f * cp[:, :2] / cp[:, 2:3] / cam['PixelSizeMm'][None, :] + cam['CenterPx'][None, :]
    want = np.stack([pixel_cols + 0.5, height - pixel_rows - 0.5], 1)
    return float(np.abs(px - want).max())


# ----------------------------------------------------------------------------- main
def grey_sphere_exponent(data_dir, photos_as='linear', min_ndl=0.2):
    """Exponent g of grey ~ (N.L)^g on the set's matte grey sphere (gray/gray.K.tga, normals from
    the mask's centroid and area-equivalent radius, inner 90 % of the radius, unsaturated samples
    with N.L > min_ndl), with the photos decoded as `photos_as`. About 1 when the decoding is
    right for a Lambertian sphere."""
    lights = read_lights(os.path.join(data_dir, 'lights.txt'))
    mask = read_tga(os.path.join(data_dir, 'gray', 'gray.mask.tga')).max(axis=2) > 127
    rows, cols = np.nonzero(mask)
    cy, cx, radius = rows.mean(), cols.mean(), np.sqrt(mask.sum() / np.pi)
    nx, ny = (cols - cx) / radius, -(rows - cy) / radius
    inner = nx ** 2 + ny ** 2 < 0.81
    normals = np.stack([nx, ny, np.sqrt(np.clip(1 - nx ** 2 - ny ** 2, 0, 1))], 1)[inner]
    x, y = [], []
    for k in range(len(lights)):
        pix = read_tga(os.path.join(data_dir, 'gray', 'gray.%d.tga' % k))[rows[inner], cols[inner]]
        grey = (srgb_to_linear(pix) if photos_as == 'srgb' else pix / 255.0).mean(axis=1)
        ndl = normals @ lights[k]
        ok = (ndl > min_ndl) & (pix.max(axis=1) < SATURATED) & (grey > 0)
        x.append(np.log(ndl[ok]))
        y.append(np.log(grey[ok]))
    x, y = np.concatenate(x), np.concatenate(y)
    design = np.stack([np.ones_like(x), x], 1)
    return float(np.linalg.lstsq(design, y, rcond=None)[0][1])


def is_seitz_set(data_dir):
    return os.path.isfile(os.path.join(data_dir, 'lights.txt'))


def load_object(data_dir, name):
    """Photos, mask and light directions of OBJECT in either set (the module docstring)."""
    return (load_seitz if is_seitz_set(data_dir) else load_harvard)(data_dir, name)


def build(data_dir, name, out_dir, heldout=None, distance=1e5, photos_as='linear', log=print):
    photos, mask, lights_all = load_object(data_dir, name)
    height, width, _ = photos[0].shape
    if any(p.shape != photos[0].shape for p in photos):
        raise InputError('%s: the photos differ in size' % os.path.join(data_dir, name))

    if heldout is None:
        heldout = default_heldout(lights_all)
    heldout = sorted(int(i) for i in heldout)
    if photos_as not in ('srgb', 'linear'):
        raise InputError('--photos must be srgb or linear')
    if len(set(heldout)) != len(heldout) or any(i < 0 or i >= len(lights_all) for i in heldout):
        raise InputError('bad held-out light indices %s' % heldout)
    train = [i for i in range(len(lights_all)) if i not in heldout]
    if len(train) < 3:
        raise InputError('fewer than 3 training lights')

    # Photometric stereo on the training lights (linear grey, mask pixels only).
    rows, cols = np.nonzero(mask)
    stack = np.stack([photos[k][rows, cols] for k in train])          # (K, N, 3) uint8
    linear = srgb_to_linear(stack) if photos_as == 'srgb' else stack / 255.0
    grey = linear.mean(axis=2)
    saturated = stack.max(axis=2) >= SATURATED
    normals, albedo, used = photometric_normals(grey, saturated, lights_all[train])
    normals_img = np.zeros((height, width, 3))
    normals_img[rows, cols] = normals
    depth_img, cg_iters, residual = integrate_depth(mask, normals_img)
    z = depth_img[rows, cols]

    # Vertices on their pixel centres through the far camera; then the skirt (see skirt()), whose
    # vertices come after the object's and are not scored (object_pixels.ply: visible = 0).
    ring_rows, ring_cols, shifts, ring_z, ring_normals, covered = skirt(mask, depth_img, normals_img)
    all_rows = np.concatenate([rows + 0.0, ring_rows + shifts[:, 0]])
    all_cols = np.concatenate([cols + 0.0, ring_cols + shifts[:, 1]])
    all_z = np.concatenate([z, ring_z])
    f_px = distance  # magnification 1 at depth 0
    u = all_cols + 0.5 - width / 2.0
    v = (height - all_rows - 0.5) - height / 2.0
    scale = (distance - all_z) / f_px
    positions = np.stack([u * scale, v * scale, all_z], 1)
    all_normals = np.concatenate([normals, ring_normals])
    idx = -np.ones((height, width), np.int64)
    idx[rows, cols] = np.arange(len(rows))
    idx[ring_rows, ring_cols] = len(rows) + np.arange(len(ring_rows))
    faces = relief_faces(covered, idx)
    on_object = np.concatenate([np.ones(len(rows), np.uint8), np.zeros(len(ring_rows), np.uint8)])

    os.makedirs(os.path.join(out_dir, 'images'), exist_ok=True)
    os.makedirs(os.path.join(out_dir, 'heldout', 'images'), exist_ok=True)
    vertices = write_ply(os.path.join(out_dir, 'mesh.ply'), positions, all_normals, faces)[:len(rows)]
    write_ply(os.path.join(out_dir, 'object_pixels.ply'), positions, all_normals, faces, on_object)
    camera = camera_attributes(width, height, distance)
    sets = [(out_dir, 'mesh.ply', train), (os.path.join(out_dir, 'heldout'), '../mesh.ply', heldout)]
    for folder, mesh_file, indices in sets:
        images = ['images/light_%02d.png' % k for k in indices]
        for k, image in zip(indices, images):
            # srgb: the 8-bit values as given (the plugin decodes 8-bit as sRGB by default);
            # linear: the same values as 16-bit (v * 257, exact), which the plugin reads as linear.
            write_png(os.path.join(folder, image),
                      photos[k] if photos_as == 'srgb' else photos[k].astype(np.uint16) * 257)
        write_mlp(os.path.join(folder, 'project.mlp'), mesh_file, images, camera)
        write_lp(os.path.join(folder, 'lights.lp'), images, lights_all[indices])

    worst = max(check_registration(os.path.join(folder, 'project.mlp'), vertices, cols, rows, height)
                for folder, _, _ in sets)
    summary = {
        'object': name, 'photos_as': photos_as, 'data_dir': os.path.abspath(data_dir), 'width': width, 'height': height,
        'train_lights': train, 'heldout_lights': heldout, 'vertices': int(len(rows)),
        'skirt_vertices': int(len(ring_rows)),
        'faces': int(len(faces)), 'camera_distance_px': distance,
        'depth_range_px': [float(z.min()), float(z.max())],
        'integration_cg_iterations': cg_iters, 'integration_rms_residual': residual,
        'samples_used_mean': float(used.mean()),
        'pixels_with_fewer_than_3_clean_samples': int((used < 3).sum()),
        'saturated_sample_share': float(saturated.mean()),
        'registration_max_error_px': worst,
    }
    with open(os.path.join(out_dir, 'psm_project.json'), 'w') as f:
        json.dump(summary, f, indent=1)
    log('%s: %d vertices, %d faces, training lights %s, held out %s, depth %.1f..%.1f px '
        '(CG %d iterations, rms residual %.3g), registration max %.2e px'
        % (name, len(rows), len(faces), train, heldout, z.min(), z.max(), cg_iters, residual, worst))
    if not worst <= REGISTRATION_TOL_PX:
        raise RegistrationError('registration check failed: a vertex projects %.4g px from its '
                                'pixel centre (limit %g)' % (worst, REGISTRATION_TOL_PX))
    return summary


class RegistrationError(Exception):
    pass


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('data_dir')
    ap.add_argument('object')
    ap.add_argument('out_dir')
    ap.add_argument('--heldout', type=int, nargs='+', default=None,
                    help='held-out light indices (default: 3 interior lights, farthest-point order)')
    ap.add_argument('--photos', choices=('srgb', 'linear'), default='linear',
                    help='how the 8-bit photos are encoded (module docstring)')
    ap.add_argument('--camera-distance', type=float, default=1e5, help='camera distance in px')
    args = ap.parse_args(argv)
    try:
        build(args.data_dir, args.object, args.out_dir, args.heldout, args.camera_distance, args.photos)
    except (InputError, OSError) as e:
        print('error: %s' % e, file=sys.stderr)
        return 2
    except RegistrationError as e:
        print('error: %s' % e, file=sys.stderr)
        return 3
    return 0


if __name__ == '__main__':
    sys.exit(main())
