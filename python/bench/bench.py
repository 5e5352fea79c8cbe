"""Measures the Python package's overhead (BENCHMARKS.md, "Python").

Run it in an environment where the package is installed from a release build
(`pip install ./python`), on a quiet machine:

    python python/bench/bench.py [--repeats 31]

1. `simulate` of the paper's 10 s run (paper_concave, its default settings) from Python,
   against the same run's Rust time inside the call (`summary["wall_time"]`: assembly and
   integration with the samples collected, what the command line's library call does):
   median of each over the repeats, their ratio, and the difference (the overhead of the
   call: argument handling, the result's arrays, the events and the summary dict).
2. `m.rhs(t, y)` per call from Python with a numpy y, and the same for `m.equations`.
3. `sweep` of 16 runs against 16 `simulate` calls.

Medians of repeats measured side by side in one run; the machine is shared, so the spread
(the interquartile range) is printed too.
"""

import argparse
import statistics
import time

import numpy as np

import camchain


def quartiles(values):
    q = statistics.quantiles(values, n=4)
    return q[0], statistics.median(values), q[2]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=31)
    args = parser.parse_args()

    m = camchain.Model("paper_concave")
    m.simulate(t_end=0.5)  # warm caches and the allocator
    outer, inner = [], []
    for _ in range(args.repeats):
        start = time.perf_counter()
        r = m.simulate()
        outer.append(time.perf_counter() - start)
        inner.append(r.summary["wall_time"])
    lo, med, hi = quartiles(outer)
    ilo, imed, ihi = quartiles(inner)
    overhead = [o - i for o, i in zip(outer, inner)]
    print(f"simulate paper_concave (t_end {r.summary['t_end']} s, {len(r)} samples, "
          f"{r.summary['steps']} steps):")
    print(f"  from Python        median {med * 1e3:.3f} ms (IQR {lo * 1e3:.3f}–{hi * 1e3:.3f})")
    print(f"  Rust run inside    median {imed * 1e3:.3f} ms (IQR {ilo * 1e3:.3f}–{ihi * 1e3:.3f})")
    print(f"  ratio {med / imed:.3f}; overhead per call median {statistics.median(overhead) * 1e6:.1f} µs")

    n = len(m.coordinates)
    y = np.concatenate([[r[f"q{i}"][0] for i in range(1, n + 1)],
                        [r[f"q{i}_dot"][0] for i in range(1, n + 1)]])
    q, qd = y[:n].copy(), y[n:].copy()
    for name, call in [("rhs", lambda: m.rhs(0.0, y)),
                       ("equations", lambda: m.equations(q, qd, 0.0)),
                       ("jacobian", lambda: m.jacobian(q))]:
        per = []
        for _ in range(args.repeats):
            calls = 20000
            start = time.perf_counter()
            for _ in range(calls):
                call()
            per.append((time.perf_counter() - start) / calls)
        lo, med, hi = quartiles(per)
        print(f"m.{name} per call: median {med * 1e6:.2f} µs (IQR {lo * 1e6:.2f}–{hi * 1e6:.2f})")

    roller = camchain.Model("cycloidal_roller")
    omegas = np.linspace(40.0, 60.0, 16)
    sweeps, loops = [], []
    for _ in range(max(3, args.repeats // 6)):
        start = time.perf_counter()
        roller.sweep({"omega": omegas}, t_end=1.0, jobs=1)
        sweeps.append(time.perf_counter() - start)
        start = time.perf_counter()
        for w in omegas:
            roller.simulate(t_end=1.0, params={"omega": float(w)})
        loops.append(time.perf_counter() - start)
    print(f"16 runs of cycloidal_roller (1 s each): sweep(jobs=1) median "
          f"{statistics.median(sweeps) * 1e3:.1f} ms, 16 simulate calls "
          f"{statistics.median(loops) * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
