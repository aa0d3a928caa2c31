#!/usr/bin/env python3
"""Compare squeal's nonlinear mode of NLvib example 05 with NLvib's.

Inputs (this folder): nlvib05_squeal.csv, nlvib05_squeal_zoom.csv (squeal
nma), nlvib05_nlvib_hb_tight_ds0.002.csv (NLvib HB, tight fsolve, dense),
nlvib05_nlvib_hb_tight_ds0.002_zoom.csv (the same, 0.1175 < A < 0.1622, step
capped), nlvib05_nlvib_hb.csv (NLvib HB as the example runs it), optionally
nlvib05_nlvib_shoot.csv. Amplitude axis: squeal's mass-normalised modal
amplitude of the first harmonic, A = sqrt(a1'M a1 + b1'M b1), computed for
NLvib's points from its harmonics (modal_amplitude_h1).
Writes nlvib05_compare.csv and nlvib05_nma.png; prints the tables.
"""
import csv, os, sys

import numpy as np
from scipy.interpolate import CubicSpline

HERE = os.path.dirname(os.path.abspath(__file__))


def load(name):
    with open(os.path.join(HERE, name)) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) if r[k] not in ("True", "False") else r[k] == "True" for r in rows])
            for k in rows[0]}


sq = load("nlvib05_squeal.csv")
sz = load("nlvib05_squeal_zoom.csv")
nl = load("nlvib05_nlvib_hb_tight_ds0.002.csv")
nd = load("nlvib05_nlvib_hb.csv")
shoot = load("nlvib05_nlvib_shoot.csv") if os.path.exists(os.path.join(HERE, "nlvib05_nlvib_shoot.csv")) else None

# NLvib curve as functions of log A (A increases monotonically along it)
lA = np.log(nl["modal_amplitude_h1"])
assert np.all(np.diff(lA) > 0), "NLvib amplitude not monotone"
f_nl = CubicSpline(lA, nl["freq_hz"])
d_nl = CubicSpline(lA, nl["damping_ratio"])
lo, hi = lA[0], lA[-1]
# NLvib's zoom run (884 points, step capped at 0.002 in log10 a) where it covers
nz = load("nlvib05_nlvib_hb_tight_ds0.002_zoom.csv")
lz = np.log(nz["modal_amplitude_h1"])
assert np.all(np.diff(lz) > 0)
fz_nl, dz_nl = CubicSpline(lz, nz["freq_hz"]), CubicSpline(lz, nz["damping_ratio"])
f_full, d_full = f_nl, d_nl
f_nl = lambda x, nu=0: np.where((x >= lz[0]) & (x <= lz[-1]), fz_nl(x, nu), f_full(x, nu))
d_nl = lambda x, nu=0: np.where((x >= lz[0]) & (x <= lz[-1]), dz_nl(x, nu), d_full(x, nu))

A = sq["modal_amplitude"]
inside = (np.log(A) >= lo) & (np.log(A) <= hi)
trans = (A > 0.12) & (A < 0.16)          # stick-to-slip transition (steep)
smooth = inside & ~trans
rf = sq["freq_hz"] / f_nl(np.log(A)) - 1
rd = sq["damping_ratio"] / d_nl(np.log(A)) - 1

out = []
print("## squeal vs NLvib (tight), at squeal's 106 amplitudes, outside 0.12 < A < 0.16")
print(f"max |rel diff| frequency {np.max(np.abs(rf[smooth])):.2e}, damping ratio {np.max(np.abs(rd[smooth])):.2e}"
      f" ({smooth.sum()} points)")
print(f"inside the transition: max |rel diff| frequency {np.max(np.abs(rf[trans & inside])):.2e}, "
      f"damping {np.max(np.abs(rd[trans & inside])):.2e} ({(trans & inside).sum()} points)")
print()
print("| A (m·√kg) | f squeal (Hz) | f NLvib (Hz) | rel. diff | D squeal | D NLvib | rel. diff |")
print("|---|---|---|---|---|---|---|")
for target in [0.0316227766, 0.05, 0.1, 0.125, 0.15, 0.2, 0.3, 0.5, 1.0, 2.0, 5.0, 10.0]:
    i = int(np.argmin(np.abs(np.log(A / target))))
    a = A[i]
    if not inside[i]:
        continue
    print(f"| {a:.4g} | {sq['freq_hz'][i]:.7f} | {float(f_nl(np.log(a))):.7f} | {rf[i]:+.1e} | "
          f"{sq['damping_ratio'][i]:.5e} | {float(d_nl(np.log(a))):.5e} | {rd[i]:+.1e} |")
for i in range(len(A)):
    out.append([A[i], sq["freq_hz"][i], float(f_nl(np.log(A[i]))) if inside[i] else "",
                rf[i] if inside[i] else "", sq["damping_ratio"][i],
                float(d_nl(np.log(A[i]))) if inside[i] else "", rd[i] if inside[i] else ""])
with open(os.path.join(HERE, "nlvib05_compare.csv"), "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["modal_amplitude", "freq_squeal_hz", "freq_nlvib_hz", "freq_rel_diff",
                "damping_squeal", "damping_nlvib", "damping_rel_diff"])
    for r in out:
        w.writerow([f"{v:.10g}" if isinstance(v, float) else v for v in r])

# The transition, resolved by squeal's zoom run (41 log-spaced amplitudes in 0.12…0.16)
Az = sz["modal_amplitude"]
rfz = sz["freq_hz"] / fz_nl(np.log(Az)) - 1
rdz = sz["damping_ratio"] / dz_nl(np.log(Az)) - 1
slope = dz_nl(np.log(Az), 1) / sz["damping_ratio"]   # dlnD/dlnA of NLvib's curve
print()
print(f"## transition zoom ({len(Az)} squeal points, 0.12 <= A <= 0.16): max |rel diff| frequency "
      f"{np.max(np.abs(rfz)):.2e}, damping ratio {np.max(np.abs(rdz)):.2e}; steepest dlnD/dlnA = {np.max(slope):.0f}")
print("| A | D squeal | D NLvib | rel. diff | dlnD/dlnA |")
print("|---|---|---|---|---|")
for i in range(0, len(Az), 4):
    print(f"| {Az[i]:.5f} | {sz['damping_ratio'][i]:.6e} | {float(dz_nl(np.log(Az[i]))):.6e} | {rdz[i]:+.1e} | {slope[i]:.0f} |")
k = int(np.argmax(nl["damping_ratio"]))
kz = int(np.argmax(sq["damping_ratio"]))
print(f"\npeak damping: NLvib D = {nl['damping_ratio'][k]:.6f} at A = {nl['modal_amplitude_h1'][k]:.5f}; "
      f"squeal (106-point grid) D = {sq['damping_ratio'][kz]:.6f} at A = {A[kz]:.5f} "
      f"(NLvib there {float(d_nl(np.log(A[kz]))):.6f})")

# NLvib as the example runs it (default fsolve tolerances) against its tight run
lAd = np.log(nd["modal_amplitude_h1"])
rdd = nd["damping_ratio"] / d_nl(lAd) - 1
rfd = nd["freq_hz"] / f_nl(lAd) - 1
okd = (lAd >= lo) & (lAd <= hi)
okd[0] = False
print(f"\nNLvib default tolerances vs tight: first point D {nd['damping_ratio'][0]:.6e} (residual "
      f"{nd['residual'][0]:.1e}) vs {float(d_nl(lAd[0])):.6e} ({rdd[0]:+.1e}); other points max |rel diff| "
      f"frequency {np.max(np.abs(rfd[okd])):.1e}, damping {np.max(np.abs(rdd[okd])):.1e} "
      f"(largest residual {np.max(nd['residual'][1:]):.1e})")
if shoot is not None:
    ls_ = np.log(shoot["modal_amplitude_h1"])
    oks = (ls_ >= lo) & (ls_ <= hi) & ~((shoot["modal_amplitude_h1"] > 0.12) & (shoot["modal_amplitude_h1"] < 0.16))
    print(f"NLvib shooting (Newmark, 1024 steps/period) vs NLvib HB tight, outside the transition: "
          f"max |rel diff| frequency {np.max(np.abs(shoot['freq_hz'][oks] / f_nl(ls_[oks]) - 1)):.1e}, "
          f"damping {np.max(np.abs(shoot['damping_ratio'][oks] / d_nl(ls_[oks]) - 1)):.1e} ({oks.sum()} points)")

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, ax = plt.subplots(3, 1, figsize=(7, 8.6), sharex=True, gridspec_kw={"height_ratios": [3, 3, 2]})
ax[0].semilogx(nl["modal_amplitude_h1"], nl["freq_hz"], "-", color="0.6", lw=3, label="NLvib HB (Octave, H=21)")
ax[0].semilogx(A, sq["freq_hz"], "o", ms=3.5, color="C3", label="squeal nma (H=21)")
ax[0].semilogx(sz["modal_amplitude"], sz["freq_hz"], "o", ms=2.5, color="C1", label="squeal nma, transition zoom")
if shoot is not None:
    ax[0].semilogx(shoot["modal_amplitude_h1"], shoot["freq_hz"], "k--", lw=1, label="NLvib shooting")
ax[0].set_ylabel("frequency (Hz)")
ax[0].legend(fontsize=8)
ax[0].grid(alpha=0.3)
ax[1].loglog(nl["modal_amplitude_h1"], nl["damping_ratio"], "-", color="0.6", lw=3, label="NLvib HB")
ax[1].loglog(A, sq["damping_ratio"], "o", ms=3.5, color="C3", label="squeal nma")
ax[1].loglog(sz["modal_amplitude"], sz["damping_ratio"], "o", ms=2.5, color="C1")
if shoot is not None:
    ax[1].loglog(shoot["modal_amplitude_h1"], shoot["damping_ratio"], "k--", lw=1, label="NLvib shooting")
ax[1].set_ylabel("modal damping ratio D")
allA = np.concatenate([A[inside & ~trans], Az])
allf = np.concatenate([np.abs(rf[inside & ~trans]), np.abs(rfz)])
alld = np.concatenate([np.abs(rd[inside & ~trans]), np.abs(rdz)])
o = np.argsort(allA)
ax[2].loglog(allA[o], np.maximum(allf[o], 1e-13), ".-", ms=3, lw=0.7, color="C0", label="|Δf/f|")
ax[2].loglog(allA[o], np.maximum(alld[o], 1e-13), ".-", ms=3, lw=0.7, color="C3", label="|ΔD/D|")
ax[2].set_ylabel("squeal vs NLvib")
ax[2].legend(fontsize=8)
ax[2].grid(alpha=0.3, which="both")
ax[2].set_xlabel("modal amplitude A = sqrt(a1'Ma1 + b1'Mb1) (m·√kg)")
ax[1].grid(alpha=0.3, which="both")
fig.suptitle("NLvib example 05 (2-dof, tanh friction, eps = 0.05 m/s): mode 1, EPMC")
fig.tight_layout()
fig.savefig(os.path.join(HERE, "nlvib05_nma.png"), dpi=90)
