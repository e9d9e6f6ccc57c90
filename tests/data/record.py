"""Record local problems u = W λ + q of demo increments for kernel/tests/test_recorded.cpp.

The kernel's solvers are tested on hand-made and random problems; these are the problems
the method really produces (finite-element flexibilities, up to 144 coupled pairs,
partial slip, turning slip). Each demo runs as it ships, with a hook on
ContactProblem.step that keeps every increment's local problem (``problem.local_problem``)
and the driver's answer (``increments[-1].lam``, ``.states``); a few representative
increments are written as ``<case>.lp`` (format: tests/data/README.md).

Run from the repository root (about 25 s on 2 cores; the same files bit for bit):
    PYTHONPATH=dolfinx_ext/python /usr/bin/python3 tests/data/record.py
"""
import os
import runpy
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


# Per demo: its arguments (none: the defaults are the coarsest meshes, which keeps the files
# at 1.3 MB) and the increments to keep, as {case name: function(records) -> index}. A
# record's "stick"/"slip"/"open" count the driver's states.
def _stick(rs, n1=2):
    # The tangential increment with the most sticking pairs (the first push). Some edge
    # pairs slip from the normal stage on (aluminium on steel: Poisson mismatch).
    return max(range(n1, len(rs)), key=lambda i: (rs[i]["stick"], -i))


def _gross(rs, n1=2):
    # The onset of gross slip: the first increment with no sticking pair.
    return min(i for i, r in enumerate(rs) if i >= n1 and r["stick"] == 0 and r["slip"] > 0)


def _turning(rs, n1=2):
    g = [i for i, r in enumerate(rs) if i >= n1 and r["stick"] == 0 and r["slip"] > 0]
    return g[len(g) // 2]  # halfway through the bend: the slip direction is turning


def _partial(rs):
    i = len(rs) - 1
    if not (rs[i]["stick"] > 0 and rs[i]["slip"] > 0):
        raise RuntimeError("the last Cattaneo-Mindlin increment is not in partial slip")
    return i


DEMOS = {
    "hertz2d": ([], {"hertz2d": lambda rs: len(rs) - 1}),
    "sliding_block": ([], {"sliding_block_stick": _stick, "sliding_block_gross_slip": _gross}),
    "cattaneo_mindlin": ([], {"cattaneo_mindlin_partial_slip": _partial}),
    "hertz3d": ([], {"hertz3d": lambda rs: len(rs) - 1}),
    "sliding_block_3d": ([], {"sliding_block_3d_turning_slip": _turning}),
}


def write(path, source, rec):
    """The format of tests/data/README.md: ASCII header, then little-endian float64."""
    W, d = rec["W"], rec["dim"]
    if not np.array_equal(W, W.T):
        raise RuntimeError(f"{path.name}: W is not exactly symmetric; the format keeps one half")
    m = rec["mu"].size
    header = [
        "flexcontact-local-problem 2",
        f"source {source}",
        f"dim {d}",
        f"pairs {m}",
        "states " + " ".join(map(str, rec["states"])),
        "states_previous " + " ".join(map(str, rec["states_prev"])),
        f"solver {rec['solver']}",
        f"residual {rec['residual']:.3e}",
        "binary float64 little-endian: mu[pairs], W upper triangle by rows, q, lambda, "
        "lambda_previous",
    ]
    iu = np.triu_indices(W.shape[0])
    data = np.concatenate([rec["mu"], W[iu], rec["q"], rec["lam"], rec["lam_prev"]])
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(data.astype("<f8").tobytes())


def record(demo):
    """Run one demo in this process with the hook, and write its cases."""
    import flexcontact.problem as fp

    args, cases = DEMOS[demo]
    records = []
    step = fp.ContactProblem.step

    def hooked(self):
        prev = self.increments[-1] if self.increments else None
        inc = step(self)
        if self.comm.rank == 0:
            lp = self.local_problem
            n = lp["q"].size
            s = inc.summary
            records.append({
                "dim": lp["dim"], "W": np.array(lp["W"], dtype=float),
                "q": np.array(lp["q"], dtype=float), "mu": np.array(lp["mu"], dtype=float),
                "lam": inc.lam.reshape(-1).copy(), "states": inc.states.copy(),
                # The driver's warm start: the previous increment's answer (zero, no states,
                # before the first one).
                "lam_prev": prev.lam.reshape(-1).copy() if prev else np.zeros(n),
                "states_prev": prev.states.copy() if prev else np.zeros(0, int),
                "solver": s.solver, "residual": s.residual,
                "stick": s.stick, "slip": s.slip, "open": s.open,
            })
        return inc

    fp.ContactProblem.step = hooked
    script = ROOT / "demos" / f"{demo}.py"
    sys.argv = [str(script), "--no-plot", *args]
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["FLEXCONTACT_RESULTS"] = tmp
        runpy.run_path(str(script), run_name="__main__")
    for name, pick in cases.items():
        i = pick(records)
        r = records[i]
        source = (f"demos/{demo}.py {' '.join(args)}".strip()
                  + f", increment {i + 1} of {len(records)}"
                  + f" (stick/slip/open {r['stick']}/{r['slip']}/{r['open']})")
        path = HERE / f"{name}.lp"
        write(path, source, r)
        print(f"{path.name}: {source}, {path.stat().st_size / 1e3:.0f} kB", flush=True)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in DEMOS:
        record(sys.argv[1])
    else:
        # One process per demo: each demo builds its gmsh model and DOLFINx mesh afresh.
        for demo in DEMOS:
            subprocess.run([sys.executable, __file__, demo], check=True, cwd=ROOT)
