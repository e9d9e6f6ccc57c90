"""The sweep's figures (matplotlib, Agg): envelopes of each output against each input, and
exceedance curves with their bootstrap band."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .quantities import quantity, three_figures

CONDITIONAL = "conditional on an impact, not an annual probability"


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _margins(fig, top_in: float = 0.4, hspace: float = 0.2) -> None:
    """Fixed margins in inches, room for the tick and axis labels and the title: what
    tight_layout found, without the extra draw of every axis it costs (a third of a
    sweep's report time)."""
    w, h = fig.get_size_inches()
    fig.subplots_adjust(left=0.7 / w, right=1.0 - 0.15 / w, bottom=0.5 / h,
                        top=1.0 - top_in / h, wspace=0.08, hspace=hspace)


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


def envelope_plots(folder: Path, rows: list, inputs: list, outputs: list,
                   dim: int = 2) -> list:
    """One PNG per output: a panel per input, every scenario and the upper envelope, in the
    report's units."""
    plt = _plt()
    paths = []
    for o in outputs:
        qo = quantity(o, dim)
        y = qo.scale * np.array([float(r["outputs"].get(o, np.nan)) for r in rows])
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
            qi = quantity(name, dim)
            x = (np.array([names.index(v) for v in raw], float) if names else
                 qi.scale * np.array([float(v) for v in raw]))
            ax.plot(x, y, ".", ms=3, alpha=0.5, label="scenarios")
            ex, ey = envelope(x, y)
            ax.plot(ex, ey, "-" if not names else "_", ms=14, color="C3",
                    label="upper envelope")
            if names:
                ax.set_xticks(range(len(names)), names)
            ax.set_xlabel(qi.label())
        for row in axes:
            row[0].set_ylabel(qo.label())
        axes[0][0].legend(fontsize=7)
        fig.suptitle(f"{qo.words}: every scenario and the upper envelope", fontsize=9)
        _margins(fig, hspace=0.45)
        path = folder / f"envelope_{o}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def exceedance_plot(folder: Path, output: str, curve: dict, dim: int = 2) -> Path:
    """Step curve of P[X > x] with its bootstrap band (log scale of P), in the report's
    units; for a stress, the concrete's tensile strength as a line with P[X > f_t] beside
    it."""
    plt = _plt()
    q = quantity(output, dim)
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    x, p = q.scale * np.array(curve["x"]), np.array(curve["p"])
    ax.fill_between(x, curve["lower"], curve["upper"], step="post", alpha=0.3,
                    label=f"{100 * curve['band']:.0f} % bootstrap band")
    ax.step(x, p, where="post", label=f"empirical, {curve['n']} scenarios")
    if (p > 0).any():
        ax.set_yscale("log")
        ax.set_ylim(0.5 / curve["n"], 1.0)
    a, ft = curve.get("above_tensile_strength"), curve.get("tensile_strength_Pa")
    if a is not None and ft is not None:
        ax.axvline(ft * q.scale, color="k", ls="--", lw=1.0,
                   label=f"tensile strength f_t = {three_figures(ft, 1e-6)} MPa")
        ax.text(0.02, 0.04, f"P[X > f_t | impact] = {three_figures(a['p'])}\n"
                f"{100 * a['band']:.0f} % band {three_figures(a['lower'])}"
                f"–{three_figures(a['upper'])}", transform=ax.transAxes, fontsize=8,
                va="bottom", bbox={"fc": "white", "ec": "0.7"})
    ax.set_xlabel(q.label())
    ax.set_ylabel("P[X > x | impact]")
    ax.set_title(f"{q.words}: exceedance\n({CONDITIONAL})", fontsize=8)
    ax.legend(fontsize=7, loc="upper right")
    _margins(fig, top_in=0.55)
    path = folder / f"exceedance_{output}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
