"""A picture of the dam mesh with its named groups coloured (2D), drawn on rank 0."""
from __future__ import annotations

import numpy as np

from .. import compat
from ..meshes import dam_tags as T
from ..errors import InputError

_BODY_COLOURS = {T.DAM: "#c9c3b8", T.FOUNDATION: "#a88f6a", T.LOG: "#7a4f1e"}
_FACET_COLOURS = {T.FOUNDATION_BOTTOM: "black", T.FOUNDATION_SIDES: "dimgray",
                  T.RESERVOIR_BED: "tab:cyan", T.TAILWATER_BED: "tab:olive",
                  T.DAM_BASE: "tab:red", T.DAM_UPSTREAM: "tab:blue", T.DAM_CREST: "tab:purple",
                  T.DAM_DOWNSTREAM: "tab:green", T.LOG_UPPER: "tab:orange",
                  T.LOG_LOWER: "gold", T.LOG_FRONT: "magenta", T.LOG_BACK: "tab:pink"}


def _gather_cells(msh, cell_tags):
    n_owned = msh.topology.index_map(2).size_local
    tag = np.zeros(n_owned, dtype=np.int32)
    keep = cell_tags.indices < n_owned
    tag[cell_tags.indices[keep]] = cell_tags.values[keep]
    x = compat.geometry_x(msh)[:, :2]
    polys = x[compat.geometry_dofmap(msh)[:n_owned]]
    return msh.comm.gather((polys, tag), root=0)


def _gather_facets(msh, facet_tags):
    x = compat.geometry_x(msh)[:, :2]
    nodes = compat.entities_to_geometry(msh, 1, facet_tags.indices.astype(np.int32))
    segs = x[nodes] if len(nodes) else np.zeros((0, 2, 2))
    return msh.comm.gather((segs, facet_tags.values), root=0)


def plot_groups(mesh, path, scenario=None) -> None:
    """Save a PNG of the 2D mesh: bodies filled, facet groups as coloured lines, the water
    level dashed. Collective (data gathered to rank 0)."""
    msh = mesh.msh
    if msh.geometry.dim != 2:
        raise InputError("plot_groups draws 2D meshes only")
    cells, facets = _gather_cells(msh, mesh.cell_tags), _gather_facets(msh, mesh.facet_tags)
    if msh.comm.rank != 0:
        return
    from matplotlib.collections import LineCollection, PolyCollection

    from ..output import pyplot
    plt = pyplot()
    polys = np.concatenate([p for p, _ in cells])
    tags = np.concatenate([t for _, t in cells])
    fig, ax = plt.subplots(figsize=(12, 6))
    ax.add_collection(PolyCollection(polys, facecolors=[_BODY_COLOURS.get(t, "w") for t in tags],
                                     edgecolors="k", linewidths=0.15))
    segs = np.concatenate([s for s, _ in facets])
    vals = np.concatenate([v for _, v in facets])
    for tag, colour in _FACET_COLOURS.items():
        sel = vals == tag
        if sel.any():
            ax.add_collection(LineCollection(segs[sel], colors=colour, linewidths=2.0,
                                             label=T.NAMES[tag]))
    if scenario is not None:
        ax.axhline(scenario.water_level_m, color="tab:blue", ls="--", lw=0.8,
                   label="water level")
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (downstream)")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right", fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_stress_histories(path, stage2, scenario) -> None:
    """PNG (rank 0) of the impact's stresses against time: the contact force, the peak
    largest principal stress at the stated offset from the impact, and the linearised
    heel and toe stresses of the base section, the contact window shaded."""
    if stage2.problem.comm.rank != 0:
        return
    from ..output import pyplot
    plt = pyplot()
    unit = "MN/m" if scenario.dim == 2 else "MN"
    rec = stage2.problem.records
    t_ms = np.array([r.t_s for r in rec]) * 1e3
    force = np.array([r.normal_force for r in rec]) * 1e-6
    met = stage2.metrics
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    axes[0].plot(t_ms, force, color="tab:red")
    axes[0].set_ylabel(f"contact force [{unit}]")
    if stage2.stress_history:
        ts, sp = np.array(stage2.stress_history).T
        axes[1].plot(ts * 1e3, sp * 1e-6, ".-", color="tab:purple",
                     label=f"peak σ₁ at {stage2.offset_m:g} m from the impact")
    axes[1].axhline(scenario.concrete_tensile_strength_Pa * 1e-6, color="k", ls="--", lw=0.8,
                    label="concrete tensile strength")
    axes[1].set_ylabel("stress [MPa]")
    axes[1].legend(fontsize=8)
    th = np.array([h[0] for h in stage2.section_history]) * 1e3
    axes[2].plot(th, [h[1].sigma_heel_Pa * 1e-6 for h in stage2.section_history],
                 label="heel (linearised)")
    axes[2].plot(th, [h[1].sigma_toe_Pa * 1e-6 for h in stage2.section_history],
                 label="toe (linearised)")
    axes[2].axhline(0.0, color="k", lw=0.5)
    axes[2].set_ylabel("base normal stress [MPa]\n(tension > 0)")
    axes[2].set_xlabel("t [ms]")
    axes[2].legend(fontsize=8)
    if met.get("contact_start_s") is not None and np.isfinite(met["contact_start_s"]):
        for ax in axes:
            ax.axvspan(met["contact_start_s"] * 1e3, met["contact_end_s"] * 1e3,
                       color="tab:orange", alpha=0.15, lw=0)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
