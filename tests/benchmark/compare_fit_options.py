#!/usr/bin/env python3
"""Fits one project twice with vbrdf_bench (the defaults, and the defaults plus --against's options)
and fails unless the defaults relight the held-out photos better: their relit CIEDE2000 mean (image
space, lit interior) at least --min-gain below the other fit's, and their whole-surface mean (every
visible lit vertex) no higher. Prints both rows.

  compare_fit_options.py --bench vbrdf_bench --project P.mlp --heldout H.mlp --gt GT.ply
                         --photos N --against "--min-heldout-photos 1" --min-gain 0.05 --work DIR

Exit status: 0 pass, 1 fail, 2 a run failed."""
import argparse
import json
import os
import shlex
import subprocess
import sys


def fit(args, name, extra):
    cmd = [args.bench, 'fit', '--project', args.project, '--backend', args.backend, '--iterations', '20',
           '--photos', str(args.photos), '--work', os.path.join(args.work, name), '--name', name,
           '--heldout', args.heldout, '--gt', args.gt] + extra
    print('$ ' + ' '.join(shlex.quote(c) for c in cmd), flush=True)
    run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = [l for l in run.stdout.splitlines() if l.startswith('RESULT ')]
    if run.returncode != 0 or not lines:
        print(run.stdout[-4000:])
        sys.exit(2)
    return json.loads(lines[-1][len('RESULT '):])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--bench', required=True)
    ap.add_argument('--project', required=True)
    ap.add_argument('--heldout', required=True)
    ap.add_argument('--gt', required=True)
    ap.add_argument('--photos', type=int, default=0)
    ap.add_argument('--backend', default='cpu')
    ap.add_argument('--against', required=True, help='extra vbrdf_bench options of the fit to beat')
    ap.add_argument('--base', default='', help='vbrdf_bench options of both fits (the stage under test alone)')
    ap.add_argument('--min-gain', type=float, default=0.0)
    ap.add_argument('--work', required=True)
    args = ap.parse_args()
    ours = fit(args, 'defaults', shlex.split(args.base))
    other = fit(args, 'against', shlex.split(args.base) + shlex.split(args.against))
    for name, r in (('defaults', ours), (args.against, other)):
        print(f"{name:28s} relit mean / p95 {r['relit_mean']:.3f} / {r['relit_p95']:.2f}, "
              f"whole surface {r['ws_mean']:.3f} / {r['ws_p95']:.2f}")
    ok = True
    if not ours['relit_mean'] <= (1 - args.min_gain) * other['relit_mean']:
        print(f"FAIL: the defaults' relit mean {ours['relit_mean']:.3f} is not {100 * args.min_gain:.1f} % "
              f"below {other['relit_mean']:.3f}")
        ok = False
    if not ours['ws_mean'] <= other['ws_mean']:
        print(f"FAIL: the defaults' whole-surface mean {ours['ws_mean']:.3f} is above {other['ws_mean']:.3f}")
        ok = False
    print('OK' if ok else 'FAILED')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
