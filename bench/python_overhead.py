"""BENCHMARKS.md's "Python" table: the cost of calling squeal from Python.

    python bench/python_overhead.py

1. squeal.stability("disc-pad", levers=False) per call (compare with
   `cargo run --release -p squeal-study --example stability_call`);
2. squeal.simulate of 1 s (200 001 × 13): wall time of the call against the
   integration time the engine itself reports (summary["timing"]["integrate_s"]);
   the difference is the analysis (spectra, verdict) plus the conversion.
"""

import time
import timeit

import squeal

n = 2000
best = min(timeit.repeat(lambda: squeal.stability("disc-pad", levers=False), number=n, repeat=5)) / n
print(f"squeal.stability(disc-pad, levers=False): {best * 1e6:.2f} µs per call (best of 5 × {n})")

for _ in range(3):
    t0 = time.perf_counter()
    run = squeal.simulate("disc-pad", duration=1.0)
    wall = time.perf_counter() - t0
    integ = run.summary["timing"]["integrate_s"]
    print(f"squeal.simulate 1 s: {run.data.shape} in {wall:.3f} s; integration {integ:.3f} s; "
          f"everything else {wall - integ:.3f} s")
