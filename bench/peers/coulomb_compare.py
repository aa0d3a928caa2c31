#!/usr/bin/env python3
"""Compare squeal's and pyHarm's frequency-response curves of the forced
Coulomb oscillator  m x'' + c x' + k x + muN sign(x') = F cos(w t)
(m = 1, k = 1e4, muN = 3, F = 10; c = 0: Den Hartog's case, with his exact
amplitude for motion without stops; c = 4: through resonance).

  coulomb_compare.py dh      -> coulomb_dh_compare.csv
  coulomb_compare.py damped  -> coulomb_damped_compare.csv
  coulomb_compare.py plot    -> coulomb_frc.png (both)

Inputs here: coulomb_<case>_squeal.csv (squeal's branch.csv), and
coulomb_<case>_pyharm_*.csv (pyharm_coulomb.py). pyHarm's curve is
interpolated (cubic, in frequency) at squeal's frequencies.
"""
import csv, glob, os, re, sys

import numpy as np
from scipy.interpolate import CubicSpline

HERE = os.path.dirname(os.path.abspath(__file__))
M, K, MUN, F = 1.0, 1.0e4, 3.0, 10.0
W0 = np.sqrt(K / M)


def den_hartog(w):
    r = w / W0
    u = np.sin(np.pi / r) / (r * (1 + np.cos(np.pi / r)))
    return F / K * np.sqrt(1 / (1 - r * r) ** 2 - (MUN / F * u) ** 2)


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def squeal(case):
    rows = read(os.path.join(HERE, f"coulomb_{case}_squeal.csv"))
    w = np.array([2 * np.pi * float(r["freq_hz"]) for r in rows])
    a = np.array([float(r["amplitude_x"]) for r in rows])
    o = np.argsort(w)
    return w[o], a[o]


def pyharm(case):
    out = {}
    for p in sorted(glob.glob(os.path.join(HERE, f"coulomb_{case}_pyharm_*.csv"))):
        tag = re.sub(rf"^coulomb_{case}_pyharm_|\.csv$", "", os.path.basename(p))
        rows = read(p)
        w = np.array([float(r["omega_rad_s"]) for r in rows])
        a = np.array([float(r["amplitude"]) for r in rows])
        o = np.argsort(w)
        out[tag] = (w[o], a[o])
    return out


def compare(case):
    ws, as_ = squeal(case)
    ph = pyharm(case)
    cols = {}
    print(f"## {case}: {len(ws)} squeal points, {ws[0]:.3f}…{ws[-1]:.3f} rad/s")
    print("| pyHarm run | points | max rel. diff vs squeal | at ω (rad/s) | mean rel. diff |"
          + (" max rel. diff vs Den Hartog |" if case == "dh" else ""))
    print("|---|---|---|---|---|" + ("---|" if case == "dh" else ""))
    for tag, (w, a) in ph.items():
        ok = (ws >= w[0]) & (ws <= w[-1])
        ai = CubicSpline(w, a)(ws[ok])
        rel = ai / as_[ok] - 1
        cols[tag] = np.full(len(ws), np.nan)
        cols[tag][ok] = ai
        j = int(np.argmax(np.abs(rel)))
        line = (f"| {tag} | {len(w)} | {rel[j]:+.2e} | {ws[ok][j]:.2f} | {np.mean(rel):+.2e} |")
        if case == "dh":
            line += f" {np.max(np.abs(a / den_hartog(w) - 1)):.2e} |"
        print(line)
    if case == "dh":
        rel = as_ / den_hartog(ws) - 1
        print(f"squeal vs Den Hartog exact: max |rel diff| {np.max(np.abs(rel)):.2e}, "
              f"range {rel.min():+.2e}…{rel.max():+.2e}")
    with open(os.path.join(HERE, f"coulomb_{case}_compare.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        hdr = ["omega_rad_s", "amp_squeal"] + [f"amp_pyharm_{t}" for t in cols]
        if case == "dh":
            hdr.append("amp_den_hartog")
        wr.writerow(hdr)
        for i in range(len(ws)):
            row = [f"{ws[i]:.8g}", f"{as_[i]:.10g}"] + [f"{cols[t][i]:.10g}" for t in cols]
            if case == "dh":
                row.append(f"{den_hartog(ws[i]):.10g}")
            wr.writerow(row)
    return ws, as_, ph


def table(case, tag, at):
    ws, as_ = squeal(case)
    w, a = pyharm(case)[tag]
    sp = CubicSpline(w, a)
    print(f"| ω (rad/s) | r | squeal | pyHarm {tag} | rel. diff |" + (" Den Hartog | squeal − DH | pyHarm − DH |" if case == "dh" else ""))
    print("|---|---|---|---|---|" + ("---|---|---|" if case == "dh" else ""))
    for x in at:
        i = int(np.argmin(np.abs(ws - x)))
        s, p = as_[i], float(sp(ws[i]))
        line = f"| {ws[i]:.3f} | {ws[i] / W0:.4f} | {s:.6e} | {p:.6e} | {p / s - 1:+.1e} |"
        if case == "dh":
            d = den_hartog(ws[i])
            line += f" {d:.6e} | {s / d - 1:+.1e} | {p / d - 1:+.1e} |"
        print(line)


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex="col", gridspec_kw={"height_ratios": [3, 2]})
    for k, case in enumerate(["dh", "damped"]):
        ws, as_ = squeal(case)
        ph = pyharm(case)
        if case == "dh":
            wd = np.linspace(ws[0], ws[-1], 400)
            ax[0, k].plot(wd / (2 * np.pi), den_hartog(wd) * 1e3, "-", color="0.75", lw=4, label="Den Hartog exact")
            ax[1, k].plot(ws / (2 * np.pi), as_ / den_hartog(ws) - 1, "k--", lw=1.2, label="squeal / Den Hartog − 1")
        for j, (tag, (w, a)) in enumerate(ph.items()):
            ax[0, k].plot(w / (2 * np.pi), a * 1e3, "-", lw=1.2, color=f"C{j}", label=f"pyHarm DLFT {tag}")
            ok = (ws >= w[0]) & (ws <= w[-1])
            ax[1, k].plot(ws[ok] / (2 * np.pi), CubicSpline(w, a)(ws[ok]) / as_[ok] - 1, "-", lw=1.2,
                          color=f"C{j}", label=f"pyHarm {tag} / squeal − 1")
        ax[0, k].plot(ws / (2 * np.pi), as_ * 1e3, "k.", ms=4, label="squeal hb --param (H=20)")
        ax[0, k].set_ylabel("amplitude of x (mm, half peak-to-peak)")
        ax[1, k].set_ylabel("relative difference")
        ax[1, k].set_xlabel("forcing frequency (Hz)")
        ax[1, k].axhline(0, color="0.5", lw=0.6)
        for a_ in ax[:, k]:
            a_.grid(alpha=0.3)
            a_.legend(fontsize=6.5)
    ax[1, 0].set_ylim(-0.06, 0.01)
    ax[1, 1].set_ylim(-0.02, 0.04)
    ax[0, 0].set_title("c = 0 (Den Hartog), r = 0.60…0.96", fontsize=9)
    ax[0, 1].set_title("c = 4 N·s/m, through resonance", fontsize=9)
    ax[0, 1].set_yscale("log")
    fig.suptitle("m x'' + c x' + k x + μN sign(x') = F cos Ωt   (m=1, k=1e4, μN=3, F=10), H = 20; "
                 "pyHarm's DLFT penalty eps and AFT samples nti in the labels", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "coulomb_frc.png"), dpi=80)


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "plot":
        plot()
    elif what == "table":
        table(sys.argv[2], sys.argv[3], [float(x) for x in sys.argv[4].split(",")])
    else:
        compare(what)
