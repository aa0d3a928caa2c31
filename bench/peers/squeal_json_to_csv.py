#!/usr/bin/env python3
"""Turn `squeal nma --json` (stdin) into a small CSV (stdout): modal
amplitude, frequency, damping ratio, xi, first-dof amplitudes, residual."""
import csv, json, sys

d = json.load(sys.stdin)
w = csv.writer(sys.stdout)
w.writerow(["modal_amplitude", "freq_hz", "damping_ratio", "xi", "amp_x1", "amp_x2", "residual", "sticks"])
for p in d["points"]:
    a = p["amplitude"]
    w.writerow([repr(p["modal_amplitude"]), repr(p["freq_hz"]), repr(p["damping_ratio"]), repr(p["xi"]),
                repr(a.get("x1")), repr(a.get("x2")), f'{p["residual"]:.3e}', p["sticks"]])
if d.get("failures"):
    print(f"# failures: {d['failures']}", file=sys.stderr)
