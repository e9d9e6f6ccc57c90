"""Wall-clock helpers shared by the bench scripts (run as scripts: bench/ is on sys.path)."""
import time

import numpy as np


def median_time(fn, n: int) -> float:
    """Median wall time (s) of n calls of fn(); a median resists the shared cores' noise."""
    ts = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))
