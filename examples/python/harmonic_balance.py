"""Harmonic balance from Python: how fast ``squeal.hb`` converges in the
number of harmonics against the shooting cycle (``squeal.cycle``), on
Hoffmann's model (contact loss) and the disc–pad (two slip reversals a
period), and the disc–pad's harmonics. (Hoffmann's error stops at 1.5e-10:
that is the shooting's own accuracy, not HB's.)

    python examples/python/harmonic_balance.py       # writes docs/python-harmonic-balance.png
    python examples/python/harmonic_balance.py DIR   # or into DIR
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import squeal  # noqa: E402

out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "docs"

fig, ax = plt.subplots(1, 2, figsize=(13, 4.6), constrained_layout=True)
for name in ("hoffmann", "disc-pad"):
    f_cycle = squeal.cycle(name)["frequency_hz"]
    hs = [1, 2, 3, 4, 8, 16, 32]
    errors = []
    for h in hs:
        r = squeal.hb(name, harmonics=h)
        errors.append(max(abs(r["freq_hz"] / f_cycle - 1.0), 1e-16))
    print(f"{name}: relative frequency error against shooting at H = {hs}: {errors}")
    ax[0].loglog(hs, errors, "o-", label=f"{name} ({f_cycle:.6g} Hz)")
ax[0].set(xlabel="harmonics H", ylabel="|f_HB / f_shooting − 1|",
          title="harmonic balance against shooting")
ax[0].legend()

r = squeal.hb("disc-pad", harmonics=40)
for dof in ("x_p", "x_d"):
    amps = r["harmonics"][dof][1:]
    ax[1].semilogy(range(1, len(amps) + 1), amps, ".-", label=dof)
ax[1].set(xlabel="harmonic k", ylabel="amplitude (m)",
          title=f"disc–pad by HB, H = 40: {r['freq_hz']:.3f} Hz, "
                f"{'stable' if r['stable'] else 'unstable'}")
ax[1].legend()
fig.savefig(out / "python-harmonic-balance.png", dpi=100)
