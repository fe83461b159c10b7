#!/usr/bin/python3
"""Markdown table of registrations' tumour figures: worst centroid error, and the tumours' axis
ratio against the truth's (largest relative gap), from report.json files.

Usage: summarize_tumours.py LABEL=REPORT.json [LABEL=REPORT.json ...]
A row per report; '*' marks a registration reported as not converged."""
import json
import sys


def main():
    print('| configuration | worst tumour error [mm] | axis ratio, registered (mean) | axis ratio, truth (mean) | '
          'largest axis-ratio gap | materials | seconds |')
    print('|---|---|---|---|---|---|---|')
    for arg in sys.argv[1:]:
        label, path = arg.split('=', 1)
        try:
            r = json.load(open(path))
        except (OSError, ValueError):
            print('| %s | failed | | | | | |' % label)
            continue
        ts = r['tumours']
        worst = max(t['centroid_distance_mm'] for t in ts)
        reg = sum(t['axis_ratio'] for t in ts) / len(ts)
        truth = sum(t['truth_axis_ratio'] for t in ts) / len(ts)
        gap = max(abs(t['axis_ratio'] - t['truth_axis_ratio']) / t['truth_axis_ratio'] for t in ts)
        mats = ', '.join('%s %.0f Pa' % (m['name'], m['youngs_modulus_Pa']) for m in r.get('materials', []))
        if 'stiffness' in r:
            mats += ' (E estimated)'
        print('| %s | %.3f%s | %.3f | %.3f | %.1f %% | %s | %.1f |' %
              (label, worst, '' if r['converged'] else '*', reg, truth, 100 * gap, mats,
               r['seconds']['registration_total'] + r['seconds'].get('prepare', 0)))


if __name__ == '__main__':
    main()
