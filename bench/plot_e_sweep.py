#!/usr/bin/env python3
"""Plots R-precision against the DLD-SIFT scale E from sweep CSV rows (bench/sweep output).

  plot_e_sweep.py OUT.png CSV [CSV ...] --series TAG=LABEL [--series ...] [--v V] [--epsilon EPS]

Each series is the rows with that tag (first CSV column), optionally only those at vocabulary size V
and KL epsilon EPS; x = scale E, y = RP_excl micro (first tier, query excluded). Needs matplotlib
(python3-matplotlib).
"""
import argparse
import csv

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ['tag', 'scale', 'V', 'epsilon', 'RP_excl_micro', 'RP_excl_macro', 'RP_incl_micro',
           'NN_micro', 'ST_micro', 'DCG_micro', 'extract_s']


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('out')
    ap.add_argument('csv', nargs='+')
    ap.add_argument('--series', action='append', required=True, help='TAG=LABEL')
    ap.add_argument('--v', type=int, default=None)
    ap.add_argument('--epsilon', type=float, default=None)
    ap.add_argument('--reference', action='append', default=[], help='LABEL=VALUE horizontal line')
    ap.add_argument('--title', default='DLD-SIFT: R-precision against the scale E')
    args = ap.parse_args()
    rows = []
    for path in args.csv:
        with open(path) as f:
            rows += [dict(zip(COLUMNS, r)) for r in csv.reader(f) if r and r[0] != 'tag']
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=110)
    for spec in args.series:
        tag, label = spec.split('=', 1)
        pts = sorted({float(r['scale']): float(r['RP_excl_micro']) for r in rows
                      if r['tag'] == tag and (args.v is None or int(r['V']) == args.v)
                      and (args.epsilon is None
                           or abs(float(r['epsilon']) - args.epsilon) <= 1e-3 * args.epsilon)}.items())
        if not pts:
            raise SystemExit(f'no rows for tag {tag} at V={args.v}, epsilon={args.epsilon}')
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker='o', label=label)
    for spec in args.reference:
        label, value = spec.split('=', 1)
        ax.axhline(float(value), linestyle='--', linewidth=1, color='gray')
        ax.text(ax.get_xlim()[0], float(value) + 0.3, label, fontsize=8, color='gray')
    ax.set_xlabel('scale E (support radius s = E * D / 2, D = enclosing-sphere diameter)')
    ax.set_ylabel('R-precision, query excluded [%]')
    ax.set_title(args.title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out)


if __name__ == '__main__':
    main()
