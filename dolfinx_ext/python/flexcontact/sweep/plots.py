"""The sweep's figures (matplotlib, Agg): envelopes of each output against each input, and
exceedance curves with their bootstrap band."""
from __future__ import annotations

from pathlib import Path

import numpy as np

CONDITIONAL = "conditional on an impact, not an annual probability"


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def envelope(x: np.ndarray, y: np.ndarray, bins: int = 10):
    """Upper envelope of y against x: the max per distinct x (a grid axis of few values)
    or per equal-count bin of x (a sample), at the bins' mean x."""
    ok = np.isfinite(y)
    x, y = x[ok], y[ok]
    ux = np.unique(x)
    if ux.size <= bins:
        return ux, np.array([y[x == v].max() for v in ux])
    order = np.argsort(x)
    parts = np.array_split(order, bins)
    return (np.array([x[p].mean() for p in parts]), np.array([y[p].max() for p in parts]))


def envelope_plots(folder: Path, rows: list, inputs: list, outputs: list) -> list:
    """One PNG per output: a panel per input, every scenario and the upper envelope."""
    plt = _plt()
    paths = []
    for o in outputs:
        y = np.array([float(r["outputs"].get(o, np.nan)) for r in rows])
        cols = min(3, len(inputs))
        rows_n = -(-len(inputs) // cols)
        fig, axes = plt.subplots(rows_n, cols, figsize=(3.4 * cols, 2.8 * rows_n),
                                 squeeze=False, sharey=True)
        for ax in axes.flat[len(inputs):]:
            ax.set_visible(False)
        for ax, name in zip(axes.flat, inputs):
            raw = [r["inputs"][name] for r in rows]
            names = sorted({v for v in raw if isinstance(v, str)})
            # A categorical input: one column of points per name, the envelope its maxima.
            x = (np.array([names.index(v) for v in raw], float) if names else
                 np.array([float(v) for v in raw]))
            ax.plot(x, y, ".", ms=3, alpha=0.5, label="scenarios")
            ex, ey = envelope(x, y)
            ax.plot(ex, ey, "-" if not names else "_", ms=14, color="C3",
                    label="upper envelope")
            if names:
                ax.set_xticks(range(len(names)), names)
            ax.set_xlabel(name)
        for row in axes:
            row[0].set_ylabel(o)
        axes[0][0].legend(fontsize=7)
        fig.suptitle(f"{o}: envelope over the sweep", fontsize=9)
        fig.tight_layout()
        path = folder / f"envelope_{o}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def exceedance_plot(folder: Path, output: str, curve: dict) -> Path:
    """Step curve of P[X > x] with its bootstrap band (log scale of P)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    x, p = np.array(curve["x"]), np.array(curve["p"])
    ax.fill_between(x, curve["lower"], curve["upper"], step="post", alpha=0.3,
                    label=f"{100 * curve['band']:.0f}% bootstrap band")
    ax.step(x, p, where="post", label=f"empirical, n = {curve['n']}")
    if (p > 0).any():
        ax.set_yscale("log")
        ax.set_ylim(0.5 / curve["n"], 1.0)
    ax.set_xlabel(output)
    ax.set_ylabel("P[X > x | impact]")
    ax.set_title(f"Exceedance of {output}\n({CONDITIONAL})", fontsize=8)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = folder / f"exceedance_{output}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
