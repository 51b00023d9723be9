"""Benchmark: resonance curve fig6a, omega in [0.5, 1.6], 400 values, up and down sweeps with
continuation, omega_a/b/c refined to 1e-4.  Run: python benchmarks/bench_resonance.py [preset]
The last line is the seconds of the timed sweep."""

import os
import sys
import time

import numpy as np

from nonsmooth import preset, resonance_curve


def main():
    name = sys.argv[1] if len(sys.argv) > 1 else "fig6a"
    p = preset(name)
    resonance_curve(p, [0.9, 1.0], transient=2, record=2)  # warm-up
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    ds = resonance_curve(p, np.linspace(0.5, 1.6, 400))
    dt = time.perf_counter() - t0
    a = ds.attrs
    print(f"resonance {name}, 400 values x 2 sweeps (transient 500 max, record 50): {dt:.2f} s, "
          f"loadavg {load0[0]:.2f} -> {os.getloadavg()[0]:.2f}")
    print(f"omega_a = {a['omega_a']:.5f}, omega_b = {a['omega_b']:.5f}, omega_c = {a['omega_c']:.5f}; "
          f"mean transient used {float(ds.transient_used.mean()):.0f} periods")
    print(f"{dt:.4f}")  # last line: seconds of the timed sweep (for ../shared/tools/side-by-side)


if __name__ == "__main__":
    main()
