"""Helpers of the end-to-end tests: PLY I/O, colour metrics, .mlx scripts, output checks.

Only the Python standard library and numpy. Tested by test_e2e_lib.py.
"""
import hashlib
import os
import re
import xml.etree.ElementTree as ET

import numpy as np

# ---------------------------------------------------------------------------------------------
# PLY (binary little endian or ASCII; what the core, vcglib and the scene generators write)

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


class Ply:
    """elements: name -> structured numpy array (scalar properties) or, for the face element,
    an (F, k) int array of vertex indices. order: element names in file order."""

    def __init__(self):
        self.elements = {}
        self.order = []
        self.comments = []

    @property
    def vertex(self):
        return self.elements["vertex"]

    @property
    def faces(self):
        return self.elements.get("face", np.zeros((0, 3), np.int64))

    def property_names(self, element="vertex"):
        arr = self.elements[element]
        return list(arr.dtype.names) if arr.dtype.names else []


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError(f"{path}: not a PLY file")
    body_start = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").splitlines()
    fmt = None
    elements = []  # (name, count, [(prop, type) or (prop, ('list', count_type, item_type))])
    ply = Ply()
    for line in header[1:]:
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "format":
            fmt = tok[1]
        elif tok[0] == "comment":
            ply.comments.append(line[8:])
        elif tok[0] == "element":
            elements.append((tok[1], int(tok[2]), []))
        elif tok[0] == "property":
            if tok[1] == "list":
                elements[-1][2].append((tok[4], ("list", _PLY_TYPES[tok[2]], _PLY_TYPES[tok[3]])))
            else:
                elements[-1][2].append((tok[2], _PLY_TYPES[tok[1]]))
    if fmt not in ("binary_little_endian", "ascii"):
        raise ValueError(f"{path}: unsupported PLY format {fmt}")
    if fmt == "ascii":
        _read_ascii_body(ply, elements, data[body_start:].decode("ascii").split())
    else:
        _read_binary_body(ply, elements, data, body_start, path)
    return ply


def _read_binary_body(ply, elements, data, offset, path):
    for name, count, props in elements:
        lists = [p for p in props if isinstance(p[1], tuple)]
        if not lists:
            dtype = np.dtype([(p, "<" + t) for p, t in props])
            arr = np.frombuffer(data, dtype=dtype, count=count, offset=offset).copy()
            offset += dtype.itemsize * count
            ply.elements[name] = arr
        elif len(props) == 1:
            _, count_t, item_t = props[0][1]
            # Fast path: every list has the same length (triangles).
            k = int(np.frombuffer(data, "<" + count_t, 1, offset)[0]) if count else 3
            dtype = np.dtype([("n", "<" + count_t), ("v", "<" + item_t, (k,))])
            if offset + dtype.itemsize * count <= len(data):
                arr = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
                if count == 0 or np.all(arr["n"] == k):
                    ply.elements[name] = arr["v"].astype(np.int64)
                    offset += dtype.itemsize * count
                    ply.order.append(name)
                    continue
            raise ValueError(f"{path}: element {name}: only constant-length lists are supported")
        else:
            raise ValueError(f"{path}: element {name}: lists mixed with scalars are not supported")
        ply.order.append(name)
    if offset != len(data):
        raise ValueError(f"{path}: {len(data) - offset} bytes after the last element (truncated header?)")


def _read_ascii_body(ply, elements, tokens):
    pos = 0
    for name, count, props in elements:
        if props and isinstance(props[0][1], tuple) and len(props) == 1:
            rows = []
            for _ in range(count):
                n = int(tokens[pos])
                rows.append([int(x) for x in tokens[pos + 1:pos + 1 + n]])
                pos += 1 + n
            ply.elements[name] = np.array(rows, np.int64).reshape(count, -1)
        else:
            dtype = np.dtype([(p, t) for p, t in props])
            arr = np.zeros(count, dtype)
            for i in range(count):
                arr[i] = tuple(float(x) for x in tokens[pos:pos + len(props)])
                pos += len(props)
            ply.elements[name] = arr
        ply.order.append(name)


def write_ply(path, vertex, faces=None, comment="written by tests/e2e"):
    """Binary little-endian PLY: `vertex` a structured array, `faces` an (F, 3) int array."""
    inv = {v: k for k, v in _PLY_TYPES.items() if k in
           ("char", "uchar", "short", "ushort", "int", "uint", "float", "double")}
    lines = ["ply", "format binary_little_endian 1.0", f"comment {comment}",
             f"element vertex {len(vertex)}"]
    for name in vertex.dtype.names:
        lines.append(f"property {inv[vertex.dtype[name].str[1:]]} {name}")
    faces = np.zeros((0, 3), np.int64) if faces is None else np.asarray(faces)
    lines += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    vdtype = np.dtype([(n, "<" + vertex.dtype[n].str[1:]) for n in vertex.dtype.names])
    fdtype = np.dtype([("n", "u1"), ("v", "<i4", (3,))])
    farr = np.zeros(len(faces), fdtype)
    farr["n"] = 3
    farr["v"] = faces
    with open(path, "wb") as f:
        f.write(("\n".join(lines) + "\n").encode("ascii"))
        f.write(vertex.astype(vdtype).tobytes())
        f.write(farr.tobytes())


# ---------------------------------------------------------------------------------------------
# Colour

def srgb_to_linear(c):
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x):
    x = np.clip(np.asarray(x, np.float64), 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


_RGB_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375],
                        [0.2126729, 0.7151522, 0.0721750],
                        [0.0193339, 0.1191920, 0.9503041]])
_WHITE_D65 = _RGB_TO_XYZ.sum(axis=1)


def linear_rgb_to_lab(rgb):
    """CIELAB (D65) of linear sRGB-primaries colours, shape (..., 3). Values above 1 are allowed."""
    xyz = np.asarray(rgb, np.float64) @ _RGB_TO_XYZ.T / _WHITE_D65
    eps, kappa = 216 / 24389, 24389 / 27
    f = np.where(xyz > eps, np.cbrt(np.maximum(xyz, eps)), (kappa * xyz + 16) / 116)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], -1)


def ciede2000(lab1, lab2):
    """CIEDE2000 colour difference (Sharma, Wu, Dalal 2005), kL = kC = kH = 1."""
    L1, a1, b1 = np.moveaxis(np.asarray(lab1, np.float64), -1, 0)
    L2, a2, b2 = np.moveaxis(np.asarray(lab2, np.float64), -1, 0)
    C1, C2 = np.hypot(a1, b1), np.hypot(a2, b2)
    Cm = (C1 + C2) / 2
    G = 0.5 * (1 - np.sqrt(Cm ** 7 / (Cm ** 7 + 25.0 ** 7)))
    a1p, a2p = (1 + G) * a1, (1 + G) * a2
    C1p, C2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1p = np.degrees(np.arctan2(b1, a1p)) % 360
    h2p = np.degrees(np.arctan2(b2, a2p)) % 360
    dLp, dCp = L2 - L1, C2p - C1p
    dh = h2p - h1p
    dh = np.where(dh > 180, dh - 360, np.where(dh < -180, dh + 360, dh))
    dh = np.where(C1p * C2p == 0, 0, dh)
    dHp = 2 * np.sqrt(C1p * C2p) * np.sin(np.radians(dh / 2))
    Lpm, Cpm = (L1 + L2) / 2, (C1p + C2p) / 2
    hsum = h1p + h2p
    hpm = np.where(np.abs(h1p - h2p) <= 180, hsum / 2, np.where(hsum < 360, (hsum + 360) / 2, (hsum - 360) / 2))
    hpm = np.where(C1p * C2p == 0, hsum, hpm)
    T = (1 - 0.17 * np.cos(np.radians(hpm - 30)) + 0.24 * np.cos(np.radians(2 * hpm))
         + 0.32 * np.cos(np.radians(3 * hpm + 6)) - 0.20 * np.cos(np.radians(4 * hpm - 63)))
    dtheta = 30 * np.exp(-(((hpm - 275) / 25) ** 2))
    Rc = 2 * np.sqrt(Cpm ** 7 / (Cpm ** 7 + 25.0 ** 7))
    Sl = 1 + 0.015 * (Lpm - 50) ** 2 / np.sqrt(20 + (Lpm - 50) ** 2)
    Sc = 1 + 0.045 * Cpm
    Sh = 1 + 0.015 * Cpm * T
    Rt = -np.sin(np.radians(2 * dtheta)) * Rc
    return np.sqrt((dLp / Sl) ** 2 + (dCp / Sc) ** 2 + (dHp / Sh) ** 2 + Rt * (dCp / Sc) * (dHp / Sh))


def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance of a dielectric of relative index eta seen from outside, at
    incidence cosine cos_i (clipped to [0, 1]; total internal reflection gives 1)."""
    cos_i = np.clip(np.asarray(cos_i, np.float64), 0, 1)
    sin_t2 = (1 - cos_i ** 2) / eta ** 2
    cos_t = np.sqrt(np.maximum(1 - sin_t2, 0))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return np.where(sin_t2 >= 1, 1.0, 0.5 * (rs ** 2 + rp ** 2))


def fit_colour_map(est, gt, mode):
    """Least-squares map M with est @ M.T ~ gt: 'scalar' (s*I), 'diag' (per channel) or 'matrix'
    (3x3). Reflectance is known up to the unknown light intensity/exposure (scalar) and, for
    photos with a camera colour cast, up to the camera's colour matrix."""
    est, gt = np.asarray(est, np.float64), np.asarray(gt, np.float64)
    if mode == "scalar":
        return np.eye(3) * (np.sum(est * gt) / np.sum(est * est))
    if mode == "diag":
        return np.diag(np.sum(est * gt, 0) / np.sum(est * est, 0))
    if mode == "matrix":
        m, *_ = np.linalg.lstsq(est, gt, rcond=None)
        return m.T
    raise ValueError(mode)


def colour_errors(est, gt, mode, dark=0.02):
    """Mean relative error |M est - gt| / |gt| and mean CIEDE2000 after the fitted map. Relative
    errors skip near-black ground truth (|gt| < dark, where they are meaningless); CIEDE2000 uses
    every vertex."""
    est, gt = np.asarray(est, np.float64), np.asarray(gt, np.float64)
    m = fit_colour_map(est, gt, mode)
    mapped = est @ m.T
    norm = np.linalg.norm(gt, axis=1)
    bright = norm >= dark
    rel = np.linalg.norm(mapped - gt, axis=1)[bright] / norm[bright]
    de = ciede2000(linear_rgb_to_lab(mapped), linear_rgb_to_lab(gt))
    return {"map": m, "mean_rel": float(rel.mean()) if rel.size else float("nan"),
            "median_rel": float(np.median(rel)) if rel.size else float("nan"),
            "dark_skipped": int((~bright).sum()),
            "mean_de2000": float(de.mean()), "p95_de2000": float(np.percentile(de, 95))}


# ---------------------------------------------------------------------------------------------
# MeshLab filter scripts (.mlx)

def write_mlx(template, out_path, values):
    """Copies the .mlx `template` with the `value` of the named <Param>s replaced. meshlabserver
    2020.09 aborts unless a script lists every parameter, so only existing ones may be set."""
    tree = ET.parse(template)
    params = {p.get("name"): p for p in tree.getroot().iter("Param")}
    for name, value in values.items():
        if name not in params:
            raise KeyError(f"{template}: no <Param name='{name}'>")
        params[name].set("value", str(value))
    body = ET.tostring(tree.getroot(), encoding="unicode")
    with open(out_path, "w", encoding="utf-8") as f:
        f.write("<!DOCTYPE FilterScript>\n" + body + "\n")


# ---------------------------------------------------------------------------------------------
# Files

def read_text(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def write_text(path, text):
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def tree_checksums(root):
    """{relative path: sha256} of every file under root (follows no links)."""
    out = {}
    for dirpath, _, files in os.walk(root):
        for name in files:
            path = os.path.join(dirpath, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = hashlib.sha256(f.read()).hexdigest()
    return out


def rewrite_mlp(src, dst, mesh_path=None, photo_dir=None):
    """Copies an .mlp with absolute paths: the mesh (mesh_path or the original one) and the photos
    (photo_dir/<file name> when given, else the original ones), so the copy works from anywhere."""
    base = os.path.dirname(os.path.abspath(src))
    text = read_text(src)

    def mesh_sub(m):
        path = mesh_path or os.path.join(base, m.group(2))
        return m.group(1) + os.path.abspath(path) + m.group(3)

    def plane_sub(m):
        name = m.group(2)
        path = os.path.join(photo_dir, os.path.basename(name)) if photo_dir else os.path.join(base, name)
        return m.group(1) + os.path.abspath(path) + m.group(3)

    text = re.sub(r'(<MLMesh[^>]*\sfilename=")([^"]*)(")', mesh_sub, text)
    text = re.sub(r'(<Plane[^>]*\sfileName=")([^"]*)(")', plane_sub, text)
    write_text(dst, text)
