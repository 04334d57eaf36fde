#!/usr/bin/python3
"""ctest driver (psm_real_projects): builds registered projects from the real photometric-stereo
sets (make_psm_project.py: the Seitz set, or the Harvard set when --data is harvard_psdata) into
a work folder, fits them with vbrdf_fit (defaults) and scores them with vbrdf_eval on the held-out
lights.

    run_psm_real.py --data DIR --workdir DIR --fit-tool vbrdf_fit --eval-tool vbrdf_eval
                    [--objects owl cat] [--photos linear|srgb] [--fit-options "--lobe re"]
                    [--decoding-check fail|warn] [--no-worse-than "--diffuse lambert" [--tolerance 0.02]]
                    [--perturb-mesh "vbrdf_perturb_mesh --smooth-normals 3 --target-median 3.5"]

Checks (each can fail):
  * the set's decoding (Seitz set only: the Harvard set has no grey sphere): on the matte grey sphere, grey ~ (N.L)^g with |g - 1| < 0.25 for the
    chosen --photos decoding (a wrong decoding gives g of about 2);
  * registration, independently of the builder's own check: every vertex of mesh.ply, projected
    with the camera of project.mlp (MeshLab's formula), lands within 0.01 px of a pixel centre,
    on a mask pixel, one vertex per mask pixel;
  * the fit runs (exit 0), its PLY has one row per mesh vertex and no NaN/inf in any property;
  * registration as the plugin samples it: over fitted vertices, the fit's diffuse colour
    (r+g+b) correlates better with the photometric-stereo albedo at the vertex's own pixel than
    at any 1-px shift (an image flip or half-pixel convention error breaks this);
  * vbrdf_eval runs on heldout/project.mlp, scores samples and prints finite figures; over the
    object's pixels (object_pixels.ply) the product is below per-pixel PTM and RBF in mean and p95;
  * with --no-worse-than OPTIONS: a second fit with those options added, and the defaults' mean and
    p95 within --tolerance of it (ctest psm_real_auto_choice: Auto's diffuse form against Lambert).
With --perturb-mesh TOOL ARGS: the relief's mesh.ply is replaced by TOOL's copy of it (mesh_exact.ply
keeps the builder's), e.g. normals smoothed as a scan's are; the checks are the same.
Printed for the record: share of vertices per fit_status, relit CIEDE2000 mean / p95.
Exit status 77 (ctest SKIP_RETURN_CODE) when the data folder is absent, 1 on a failed check.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_psm_project as psm  # noqa: E402

SKIP = 77
PLY_TYPES = {'float': '<f4', 'float32': '<f4', 'double': '<f8', 'uchar': 'u1', 'uint8': 'u1',
             'int': '<i4', 'int32': '<i4', 'uint': '<u4', 'short': '<i2', 'ushort': '<u2'}


def read_ply_vertices(path):
    """Vertex table of a binary little-endian PLY (vertex element first) as a structured array."""
    with open(path, 'rb') as f:
        data = f.read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    header = data[:end].decode('ascii').splitlines()
    if 'format binary_little_endian 1.0' not in header:
        raise ValueError('%s: not binary little-endian' % path)
    count, props, in_vertex = 0, [], False
    for line in header:
        t = line.split()
        if t and t[0] == 'element':
            in_vertex = t[1] == 'vertex'
            if in_vertex:
                count = int(t[2])
        elif t and t[0] == 'property' and in_vertex:
            if t[1] == 'list':
                raise ValueError('%s: list property in vertex element' % path)
            props.append((t[2], PLY_TYPES[t[1]]))
    return np.frombuffer(data, np.dtype(props), count, end)


def check_registration(out_dir, mask):
    """Independent re-projection of mesh.ply through project.mlp; returns a list of failures."""
    vert = read_ply_vertices(os.path.join(out_dir, 'mesh.ply'))[:int(mask.sum())]  # the skirt follows
    cam = psm.parse_camera(os.path.join(out_dir, 'project.mlp'))
    rot = cam['RotationMatrix'].reshape(4, 4)[:3, :3]
    pos = np.stack([vert['x'], vert['y'], vert['z']], 1).astype(np.float64)
    cp = (pos + cam['TranslationVector'][:3]) @ rot.T
    cp[:, 2] = -cp[:, 2]
    px = cam['FocalMm'][0] * cp[:, :2] / cp[:, 2:3] / cam['PixelSizeMm'] + cam['CenterPx']
    height = int(cam['ViewportPx'][1])
    col, row = px[:, 0] - 0.5, height - px[:, 1] - 0.5   # top-down row of the pixel centre
    ci, ri = np.round(col).astype(int), np.round(row).astype(int)
    err = np.maximum(np.abs(col - ci), np.abs(row - ri))
    failures = []
    if not np.all(cp[:, 2] > 0):
        failures.append('vertices behind the camera')
    if err.max() > psm.REGISTRATION_TOL_PX:
        failures.append('a vertex projects %.3g px from a pixel centre' % err.max())
    inside = (ci >= 0) & (ci < mask.shape[1]) & (ri >= 0) & (ri < mask.shape[0])
    if not inside.all() or not mask[ri[inside], ci[inside]].all():
        failures.append('vertices outside the mask')
    if len(set(zip(ri.tolist(), ci.tolist()))) != len(vert) or len(vert) != int(mask.sum()):
        failures.append('not one vertex per mask pixel (%d vertices, %d mask pixels)'
                        % (len(vert), int(mask.sum())))
    print('  registration: %d vertices, max %.2e px from their pixel centres' % (len(vert), err.max()))
    return failures


def sampling_check(args, name, fit, mask):
    """Correlation of the fit's diffuse colour with the photometric-stereo albedo at the vertex's
    pixel and at the four 1-px shifts; returns a list of failures."""
    rows, cols = np.nonzero(mask)   # the builder's vertex order
    all_photos, _, lights = psm.load_object(args.data, name)
    with open(os.path.join(args.workdir, name, 'psm_project.json')) as f:
        train = json.load(f)['train_lights']
    photos = np.stack([all_photos[k] for k in train])
    fit = fit[:len(rows)]  # the object's vertices; the skirt follows
    fitted = fit['fit_status'] > 0
    diffuse = (fit['diffuse_r'] + fit['diffuse_g'] + fit['diffuse_b'])[fitted]
    corr = {}
    for dr, dc in [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]:
        rr = np.clip(rows + dr, 0, mask.shape[0] - 1)
        cc = np.clip(cols + dc, 0, mask.shape[1] - 1)
        stack = photos[:, rr, cc]
        lin = psm.srgb_to_linear(stack) if args.photos == 'srgb' else stack / 255.0
        _, albedo, _ = psm.photometric_normals(lin.mean(axis=2), stack.max(axis=2) >= psm.SATURATED, lights[train])
        corr[(dr, dc)] = float(np.corrcoef(diffuse, albedo[fitted])[0, 1])
    print('  diffuse colour vs PS albedo, correlation at shifts (row, col): '
          + ', '.join('%s %.4f' % (k, v) for k, v in corr.items()))
    best_shift = max((v, k) for k, v in corr.items() if k != (0, 0))
    if not corr[(0, 0)] > best_shift[0]:
        return ['%s: the fit samples the photos off the vertex pixels (shift %s correlates better)'
                % (name, best_shift[1])]
    return []


def run(cmd):
    print('  $ ' + ' '.join(cmd))
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    return p.returncode, p.stdout


def check_object(args, name):
    failures = []
    out = os.path.join(args.workdir, name)
    shutil.rmtree(out, ignore_errors=True)
    try:
        psm.build(args.data, name, out, photos_as=args.photos, log=lambda s: print('  ' + s))
    except psm.RegistrationError as e:
        return ['%s: builder: %s' % (name, e)]
    _, mask, _ = psm.load_object(args.data, name)
    failures += ['%s: %s' % (name, f) for f in check_registration(out, mask)]
    if args.perturb_mesh:
        mesh, exact = os.path.join(out, 'mesh.ply'), os.path.join(out, 'mesh_exact.ply')
        os.replace(mesh, exact)
        tool, *tool_args = args.perturb_mesh.split()
        rc, text = run([tool, exact, mesh] + tool_args)
        print('   ' + text.strip().replace('\n', '\n   '))
        if rc != 0:
            return failures + ['%s: %s exited %d' % (name, tool, rc)]

    fit_ply = os.path.join(out, 'fit.ply')
    rc, text = run([args.fit_tool, os.path.join(out, 'project.mlp'), '--out', fit_ply] + args.fit_options.split())
    if rc != 0 or not os.path.exists(fit_ply):
        print(text)
        return failures + ['%s: vbrdf_fit exited %d' % (name, rc)]
    for line in text.splitlines():
        if re.search(r'grazing light|no usable sample \(|full fits|vertices coloured', line):
            print('   ' + line.strip())
    fit = read_ply_vertices(fit_ply)
    n_mesh = len(read_ply_vertices(os.path.join(out, 'mesh.ply')))
    if len(fit) != n_mesh:
        failures.append('%s: fit has %d vertices, mesh %d' % (name, len(fit), n_mesh))
    bad = [p for p in fit.dtype.names if fit.dtype[p].kind == 'f' and not np.all(np.isfinite(fit[p]))]
    if bad:
        failures.append('%s: NaN/inf in %s' % (name, ', '.join(bad)))
    if 'fit_status' in fit.dtype.names:
        status = fit['fit_status']
        shares = ', '.join('%d: %.1f %%' % (s, 100.0 * np.mean(status == s)) for s in np.unique(status))
        print('  fit_status shares (of %d vertices): %s' % (len(status), shares))
        # Every object pixel is in view by construction (and every seen vertex must have a model), so
        # one without a model means the builder or the visibility lost it (e.g. an edge-on normal).
        obj = read_ply_vertices(os.path.join(out, 'object_pixels.ply'))
        if 'visible' in obj.dtype.names and len(obj) == len(status):
            on_object = obj['visible'] > 0
            no_model = int(np.sum(on_object & (status == 0)))
            print('  object pixels without a model: %d of %d' % (no_model, int(on_object.sum())))
            if no_model:
                failures.append('%s: %d object pixels without a model' % (name, no_model))
        if not failures:
            failures += sampling_check(args, name, fit, mask)

    # Acceptance: over every object pixel (one vertex per pixel) at the held-out lights,
    # the product below per-pixel PTM and RBF fitted on the same training photos, in mean and p95,
    # and no seen vertex without a model.
    rc, rows, unmodelled = score(args, out, fit_ply)
    if len(rows) != 3 or not unmodelled:
        failures.append('%s: vbrdf_eval output not understood (exit %d)' % (name, rc))
        return failures
    if not all(np.isfinite(v[1]) and np.isfinite(v[2]) and v[0] > 0 for v in rows.values()):
        failures.append('%s: vbrdf_eval figures not finite or no samples' % name)
    print('  RESULT %s: whole surface relit CIEDE2000 mean/p95: product %.3f/%.3f, PTM %.3f/%.3f, RBF %.3f/%.3f; '
          'seen vertices without a model %s of %s' % (name, rows['product'][1], rows['product'][2], rows['ptm'][1],
                                                      rows['ptm'][2], rows['rbf'][1], rows['rbf'][2],
                                                      unmodelled.group(1), unmodelled.group(2)))
    if rc != 0:
        failures.append('%s: product not below both per-pixel baselines in mean and p95 (vbrdf_eval exit %d)' % (name, rc))
    if int(unmodelled.group(1)) != 0:
        failures.append('%s: %s seen vertices without a model' % (name, unmodelled.group(1)))
    if args.no_worse_than:
        failures += compare_with(args, name, out, rows['product'])
    return failures


def score(args, out, fit_ply):
    """vbrdf_eval over the object's pixels at the held-out lights: exit status, {product, ptm, rbf:
    (samples, mean, p95)} and the 'seen vertices without a model' match."""
    rc, text = run([args.eval_tool, '--result', fit_ply, '--project', os.path.join(out, 'heldout', 'project.mlp'),
                    '--training', os.path.join(out, 'project.mlp'), '--below-baselines',
                    '--gt-visible', os.path.join(out, 'object_pixels.ply')])
    print('\n'.join('   ' + l for l in text.splitlines()))
    rows = {}
    for label, key in (('whole surface: product', 'product'), ('same samples: PTM', 'ptm'),
                       ('same samples: RBF', 'rbf')):
        m = re.search(re.escape(label) + r'[^\n]*?\s(\d+)\s+([-\d.naif]+)\s+([-\d.naif]+)\s+([-\d.naif]+)\n', text)
        if m:
            rows[key] = (int(m.group(1)), float(m.group(2)), float(m.group(4)))
    return rc, rows, re.search(r'seen vertices without a model: (\d+) of (\d+)', text)


def compare_with(args, name, out, product):
    """The defaults must not relight worse than a fixed choice (--no-worse-than OPTIONS, e.g.
    "--diffuse lambert": Auto's pilot must not pick a form that loses on the real held-out lights)."""
    ref_ply = os.path.join(out, 'fit_reference.ply')
    rc, text = run([args.fit_tool, os.path.join(out, 'project.mlp'), '--out', ref_ply] +
                   (args.fit_options + ' ' + args.no_worse_than).split())
    if rc != 0 or not os.path.exists(ref_ply):
        print(text)
        return ['%s: vbrdf_fit %s exited %d' % (name, args.no_worse_than, rc)]
    _, rows, _ = score(args, out, ref_ply)
    if 'product' not in rows:
        return ['%s: vbrdf_eval output of the reference fit not understood' % name]
    ref = rows['product']
    print('  RESULT %s: defaults %.3f/%.3f, with %s %.3f/%.3f' % (name, product[1], product[2], args.no_worse_than,
                                                               ref[1], ref[2]))
    tol = 1.0 + args.tolerance
    if product[1] > tol * ref[1] or product[2] > tol * ref[2]:
        return ['%s: the defaults relight worse (%.3f/%.3f) than with %s (%.3f/%.3f)'
                % (name, product[1], product[2], args.no_worse_than, ref[1], ref[2])]
    return []


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--data', required=True)
    ap.add_argument('--workdir', required=True)
    ap.add_argument('--fit-tool', required=True)
    ap.add_argument('--eval-tool', required=True)
    ap.add_argument('--objects', nargs='+', default=['owl', 'cat'])
    ap.add_argument('--photos', choices=('linear', 'srgb'), default='linear')
    ap.add_argument('--fit-options', default='', help='extra vbrdf_fit options, e.g. "--lobe re"')
    ap.add_argument('--no-worse-than', default='',
                    help='also fit with these extra options and fail if the defaults relight worse (mean or '
                         'p95 beyond --tolerance), e.g. "--diffuse lambert"')
    ap.add_argument('--tolerance', type=float, default=0.02)
    ap.add_argument('--perturb-mesh', default='',
                    help='a tool and its options that write a changed copy of the mesh (TOOL IN OUT ARGS), e.g. '
                         '"vbrdf_perturb_mesh --smooth-normals 3 --target-median 3.5"')
    ap.add_argument('--decoding-check', choices=('fail', 'warn'), default='fail',
                    help='the grey sphere says whether the decoding is linear; warn: only print it')
    args = ap.parse_args()
    seitz = psm.is_seitz_set(args.data)
    if not seitz and not all(os.path.isfile(os.path.join(args.data, o, 'light_directions.txt')) for o in args.objects):
        print('SKIP: real photometric-stereo set not found at %s (see docs/testing.md: it lives in '
              '../shared beside the repository and is not part of it)' % args.data)
        return SKIP
    failures = []
    if seitz:
        exponent = psm.grey_sphere_exponent(args.data, args.photos)
        print('grey sphere: grey ~ (N.L)^%.3f with the photos decoded as %s' % (exponent, args.photos))
        if abs(exponent - 1.0) >= 0.25:
            message = 'grey sphere exponent %.3f: decoding %s is not linear in radiance' % (exponent, args.photos)
            if args.decoding_check == 'fail':
                failures.append(message)
            else:
                print('warning: ' + message)
    else:
        print('Harvard set: no grey sphere to check the decoding (%s as asked)' % args.photos)
    os.makedirs(args.workdir, exist_ok=True)
    for name in args.objects:
        print('== %s' % name)
        failures += check_object(args, name)
    for f in failures:
        print('FAIL: ' + f)
    print('OK' if not failures else '%d check(s) failed' % len(failures))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
