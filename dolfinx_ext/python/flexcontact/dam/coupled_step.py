"""One impact scenario from a factored DamModel and LogModel: the bodies are coupled only
through contact (docs/architecture.md §7, per-body condensation).

The contact nodes are the placed log's front-end nodes (slaves, first) and the nodes of the
dam's face strip (masters, node–surface, paired once as stage 2 does). The kernel's F̂ is
block-diagonal, [F̂_log (rotated), F̂_face]: in 3D (``fhat``, :data:`FHAT`) the kernel holds
the two models' blocks, shared by every scenario, and the stepper makes the products with
them (docs/architecture.md §7, "Blocks shared between runs"). Each Moreau–Jean step
(θ-scheme, dynamics.py) goes through the stepper for separately condensed bodies
(stepper.BodiesStepper):

1. each body's right-hand side h[−K (w + hθ ω)], condensed onto its contact DOFs with its
   own factor, skipped while the body has received no impulse (it is then exactly at
   rest, or in rigid flight for the log);
2. the kernel's contact step on the contact DOFs (one crossing of the binding);
3. each body's velocity change Δω = Ŵ_b⁻¹ (r_b + S_bᵀ P_b) by its expansion: with the
   condensation, one back-substitution per body and step;
4. w ← w + h (θ ω⁺ + (1 − θ) ω⁻) per body.
"""
from __future__ import annotations

import math
import time
from types import SimpleNamespace
from typing import Optional

import numpy as np

from .. import _cpp
from ..condensation import kernel_pairs
from ..pairing import pair_caps
from ..impact_output import contact_metrics, filter_steps, force_at_filtered_peak
from ..postprocess import impact_step_forces, peak_pressure_Pa
from ..shared_solves import Solve, serve_alone, shares
from ..stepper import BodiesStepper, CondensedBody
from ..surface_pairs import build_surface_pairs
from .key_numbers import halfspace_tension_Pa
from .stage2 import (MARGIN, approach_time_s, force_filter_window_s, log_crushing_strength_Pa,
                     response_duration_s)


def expected_contact_s(s, dam) -> float:
    """2L/c of the log along the face normal (x): its x-extent at the bar wave speed; the
    dam's own round trip (base width) is added as a bound as stage 2 does."""
    c_log = math.sqrt(s.wood.E_Pa / (s.wood.rho_kg_m3 * (1.0 + s.added_mass_coefficient)))
    a = s.log_axis
    extent = s.log_length_m * abs(a[0]) + s.log_diameter_m * math.sqrt(max(1.0 - a[0] ** 2,
                                                                           0.0))
    c_dam = math.sqrt(s.concrete.E_Pa / s.concrete.rho_kg_m3)
    return min(2.0 * extent / c_log, 2.0 * s.base_width_m / c_dam)


def run_steps(s, dam) -> int:
    """Time steps of scenario ``s``'s run: long enough for the base, whose moment peaks about
    half the dam's first period after the impact, well after the contact has ended
    (stage2.response_duration_s)."""
    duration = max(approach_time_s(s) + MARGIN * expected_contact_s(s, dam),
                   response_duration_s(s))
    return int(round(duration / dam.dt))


class _Body:
    """Displacement w and velocity ω of one body (PETSc Vecs), at rest until pushed."""

    def __init__(self, model):
        self.model, self.w, self.omega = model, model.new_vector(), model.new_vector()
        self.pushed = False

    def rhs(self):
        """h[−K (w + hθ ω)] (a new Vec), or None while at rest (then it is exactly zero)."""
        return self.model.step_rhs(self.w, self.omega) if self.pushed else None

    def advance(self, dv, h: float, theta: float) -> None:
        v_new = self.omega.copy()
        if dv is not None:
            v_new.axpy(1.0, dv)
            dv.destroy()
            self.pushed = True
        self.w.axpy(h * theta, v_new)
        self.w.axpy(h * (1.0 - theta), self.omega)
        self.omega.destroy()
        self.omega = v_new


def _dam_solve_counter(dam):
    def count():
        dam.back_substitutions["dam_stage2"] += 1
    return count


def _log_solve_counter(log):
    def count():
        log.back_substitutions += 1
    return count


AFTER_CONTACT = ("convolve", "step")
"""How the dam's base section is followed after the last contact step: "convolve" (its
response functions, dam/response.py: no dam back-substitution) or "step" (the dam stepped
to the end)."""


FHAT = ("auto", "shared", "dense")
"""How the kernel holds F̂ = diag(F̂_log, F̂_face): "shared" (the log's and the face's blocks,
held once by their models and shared by every scenario, the log's turned by its placement;
W_eff's columns fetched for the pairs that close), "dense" (F̂ and W_eff formed whole for
each scenario: 380 MB at the main job's mesh) or "auto": "shared" where the dam's factor
shares its solves between scenarios (MUMPS's Schur factor: the 3D block), "dense" for a
split factor (the 2D section, whose blocks are a few hundred DOFs: there the stepper's
products cost more than the kernel's, 0.23 s against 0.14 s a scenario)."""


def holds_shared_blocks(fhat: str, dam) -> bool:
    """Whether a run with ``fhat`` (:data:`FHAT`) on ``dam`` holds the models' blocks."""
    if fhat not in FHAT:
        raise ValueError(f"fhat={fhat!r}: one of {FHAT}")
    return fhat == "shared" or (fhat == "auto" and shares(dam.factor))


def _kernel(d, dam, log, R, pairs, mu: float, h: float, theta: float, shared: bool):
    m = pairs.m
    if shared:
        # Room for every pair's columns of W_eff: the index set never asks for more.
        room = 8.0 * (d * m) ** 2 + 1.0
        return _cpp.FactorImpact.dense_blocks(
            d, [log.front_block, dam.face_block], [R, None], pairs.x, kernel_pairs(pairs),
            np.full(m, mu), 0.0, h, theta, _cpp.SolverOptions(), room)
    # Column-major, as the kernel holds it: handed over by a plain copy, not a transpose.
    F = np.zeros((d * pairs.x.shape[0],) * 2, order="F")
    F[:d * m, :d * m] = log.W_front_global(R)
    F[d * m:, d * m:] = dam.W_face
    return _cpp.ImpactContact(d, F, pairs.x, kernel_pairs(pairs), np.full(m, mu), 0.0, h,
                              theta, None, _cpp.SolverOptions())


def run_impact(dam, log, s, static, offset_m: float = 1.0,
               after_contact: str = "convolve", histories: bool = False,
               timings: Optional[dict] = None, fhat: str = "auto") -> dict:
    """The impact of scenario ``s`` alone (:func:`impact_run`, its solves made one by one)."""
    return serve_alone(impact_run(dam, log, s, static, offset_m, after_contact, histories,
                                  timings, fhat))


def impact_run(dam, log, s, static, offset_m: float = 1.0,
               after_contact: str = "convolve", histories: bool = False,
               timings: Optional[dict] = None, fhat: str = "auto"):
    """The impact of scenario ``s`` (a DamScenario) from the static state ``static`` of
    ``dam`` at its water level, with ``log`` (the LogModel of its log), as a generator of
    its solves (shared_solves: served alone by :func:`run_impact`, or beside other
    scenarios' by ScenarioEvaluator.evaluate_many). Returns the outputs
    (plain floats, see ScenarioEvaluator.evaluate); with ``histories``, also
    "history": {section quantity: its change after each step} and "face_impulses".

    ``after_contact="convolve"``: once the log has left the face and the dam's energy
    cannot bring the face back to it (:func:`_cannot_touch`), the dam is no longer stepped:
    only the log is, and the base section's history comes from the convolution of the face
    impulses with its response functions. Should the log come back within that bound, the
    dam is stepped again from where it stopped (its back-substitutions counted).

    ``fhat``: how the kernel holds F̂ (:data:`FHAT`).

    ``timings``: a dict to which the seconds of the steps with the dam stepped
    ("coupled_steps_s"), of those with the log alone ("log_only_steps_s") and of the
    convolution ("convolution_s") are added (wall time: beside other runs, theirs too)."""
    if after_contact not in AFTER_CONTACT:
        raise ValueError(f"after_contact={after_contact!r}: one of {AFTER_CONTACT}")
    h, theta, d = dam.dt, dam.theta, s.dim
    shared = holds_shared_blocks(fhat, dam)
    R = log.placement(s)
    slave = log.placed_front(R, s.log_centre)
    pairs = build_surface_pairs([("node_to_surface", slave, dam.face)], d)
    m = pairs.m
    n_log = d * m
    kernel = _kernel(d, dam, log, R, pairs, s.friction_mu, h, theta, shared)
    sigma_c = log_crushing_strength_Pa(s)
    if sigma_c is not None:
        pairs.crushing_strength = np.full(m, sigma_c)
        kernel.set_crushing(pair_caps(pairs))
    V0 = s.log_speed_m_s * np.asarray(s.log_axis, float)
    bd, bl = _Body(dam), _Body(log)
    u_face0 = static.u.x.array[dam.face_dofs]
    impact = np.array(s.log_front_point, float)
    impact[0] = 0.0  # on the face
    probe = dam.stress_probe(impact, offset_m)
    static_stress = dam.static_stress_Pa(static, probe) if d == 3 else None
    n = run_steps(s, dam)
    if after_contact == "convolve":
        # Tabulated now, before this run's first request: the lags it may convolve with
        # cost back-substitutions with the dam's factor, which must not fall between another
        # run's condensation and its expansion on that factor (shared_solves).
        dam.responses().ensure(n)
    records, peak_principal, p_peak = [], -math.inf, 0.0
    section = {q: np.zeros(n) for q in dam.section_gradients}
    impulses = np.zeros((n, dam.face_dofs.size))
    alone = {"dam": 0, "log": 0}  # this run's solves outside the stepper (beside other runs,
    # the models' own counters also count theirs)
    stepper = BodiesStepper(kernel, [
        CondensedBody("log", log.factor, log.front_dofs, log.new_vector, rotation=R,
                      counted=_log_solve_counter(log),
                      flexibility=log.front_block if shared else None),
        CondensedBody("dam", dam.factor, dam.face_dofs, dam.new_vector,
                      counted=_dam_solve_counter(dam),
                      flexibility=dam.face_block if shared else None)],
        expand_key="velocity_change_c")
    dam_slice = slice(n_log, n_log + dam.face_dofs.size)   # the kernel's DOFs: log, then dam
    face_x = pairs.x[m:, 0] + u_face0[0::d]   # the face nodes' static x (m)
    stopped, touched, last_contact = None, False, -1
    clock = {"coupled_steps_s": 0.0, "log_only_steps_s": 0.0, "convolution_s": 0.0}
    for i in range(n):
        t_step = time.perf_counter()
        t = i * h
        u_log = _log_values(log, bl.w, R, V0 * t)
        if stopped is not None:
            if _cannot_touch(pairs.x[:m], u_log, _log_values(log, bl.omega, R, V0), face_x,
                             stopped["bound"], h, _crush_recess(kernel, pairs)):
                bl.advance((yield from _free_log_step(log, bl, alone)), h, theta)
                records.append(SimpleNamespace(t_s=(i + 1) * h, active=0, normal_force=0.0))
                clock["log_only_steps_s"] += time.perf_counter() - t_step
                continue
            # back to stepping
            yield from _replay(dam, bd, stopped["step"], i, h, theta, section, alone)
            stopped = None
        u_c = np.concatenate([u_log, u_face0 + bd.w.array_r[dam.face_dofs]])
        v_c = np.concatenate([_log_values(log, bl.omega, R, V0),
                              bd.omega.array_r[dam.face_dofs]])
        rhs = [bl.rhs(), bd.rhs()]
        out, (dv_l, dv_d) = yield from stepper.advance_requests(
            rhs, where=f"time step {i + 1}", before=(u_c, v_c), free_shift=v_c)
        for b in rhs:
            if b is not None:
                b.destroy()
        impulses[i] = np.asarray(out["reaction"])[dam_slice]
        bd.advance(dv_d, h, theta)
        bl.advance(dv_l, h, theta)
        active = int(np.asarray(out["active"], bool).sum())
        records.append(SimpleNamespace(t_s=(i + 1) * h, active=active,
                                       normal_force=float(out["normal_impulse"]) / h))
        if bd.pushed:
            for q, v in dam.section_change(bd.w).items():
                section[q][i] = v
        if active > 0:
            touched, last_contact = True, i
            peak_principal = max(peak_principal, dam.peak_principal_Pa(static, bd.w, probe))
            p_peak = max(p_peak, peak_pressure_Pa(impact_step_forces(out, h), pairs,
                                                  slave_only=True))
        elif after_contact == "convolve" and touched and i + 1 < n:
            # Without impulse the scheme's energy never grows (it loses (θ − ½)(‖Δv‖²_M +
            # ‖Δu‖²_K) a step), so the energy of now bounds the face's motion for good.
            bound = np.sqrt(2.0 * max(dam.energy_J(bd.w, bd.omega), 0.0)
                            * dam.face_compliance(0))
            stopped = {"step": i + 1, "bound": bound}
        clock["coupled_steps_s"] += time.perf_counter() - t_step
    t_conv = time.perf_counter()
    if stopped is not None:
        # The base section after the last stepped step, from the whole impulse history.
        k0 = stopped["step"]
        conv = dam.responses().convolve(impulses[:last_contact + 1], n)
        for q in section:
            section[q][k0:] = conv[q][k0:]
    clock["convolution_s"] += time.perf_counter() - t_conv
    if timings is not None:
        for k, v in clock.items():
            timings[k] = timings.get(k, 0.0) + v
    # The section is zero before the first impulse, so these extremes never pass the
    # static values the wrong way.
    heel = static.section.sigma_heel_Pa + float(section["sigma_heel_Pa"].max())
    out = _outputs(s, dam, log, static, records, h, bl, R, heel, peak_principal, p_peak,
                   offset_m, n)
    if d == 3:
        # The face impulses are the dam's (x along its inward normal, as the normal force).
        forces = impulses.reshape(n, -1, d).sum(axis=1) / h
        force = force_at_filtered_peak([r.normal_force for r in records], forces,
                                       filter_steps(force_filter_window_s(s), h))
        out["halfspace_tension_Pa"] = halfspace_tension_Pa(s, force, static_stress, offset_m)
    out.update(_section_outputs(static, section))
    out["dam_back_substitutions"] = stepper.back_substitutions["dam"] + alone["dam"]
    out["log_back_substitutions"] = stepper.back_substitutions["log"] + alone["log"]
    out["dam_steps_convolved"] = int(n - stopped["step"]) if stopped is not None else 0
    if histories:
        out["history"] = section
        out["face_impulses"] = impulses[:last_contact + 1]
    return out


def _section_outputs(static, section: dict) -> dict:
    """The base section's extremes during the run: the most compressive toe stress and the
    largest changes of its normal force and moment (static values, no change, if the log
    never touched)."""
    return {"toe_stress_impact_Pa": (static.section.sigma_toe_Pa
                                     + float(section["sigma_toe_Pa"].min())),
            "base_normal_force_change_N_per_m": float(np.abs(section["normal_force_N"]).max()),
            "base_moment_change_Nm_per_m": float(np.abs(section["moment_centre_Nm"]).max())}


def _crush_recess(kernel, pairs) -> Optional[np.ndarray]:
    """Per front node, the x by which its crushed surface lies behind the node (≤ 0 as the
    face's normal points at the log): δ n_x, or None if the interface cannot crush."""
    if pairs.crushing_strength is None:
        return None
    delta = np.asarray(kernel.node_crush_depth)[:pairs.m]
    return delta * np.asarray(pairs.normal)[:, 0]


def _cannot_touch(x_log, u_log, v_log, face_x, bound, h: float,
                  recess: Optional[np.ndarray] = None) -> bool:
    """Whether the log's front cannot reach the face within the next step: its nodes
    (reference ``x_log`` + ``u_log``, moving at ``v_log``) stay behind every face node's
    static x less its energy ``bound``, by two steps of their own motion. A crushed node
    re-contacts from its crushed surface (docs/crushing.md), ``recess`` (δ n_x) behind it:
    without it, the crushed end would seem to reach into the face for ever."""
    d = x_log.shape[1]
    x = x_log[:, 0] + u_log[0::d]
    front = (x if recess is None else x + recess).max()
    reach = 2.0 * h * np.abs(v_log[0::d]).max()
    return bool(front + reach < (face_x - bound).min())


def _free_log_step(log, body, counts: dict):
    """The log's velocity change in a step without contact (None while it flies rigidly);
    a generator of its one solve, counted in ``counts["log"]`` and the log's counter."""
    b = body.rhs()
    if b is None:
        return None
    y = log.new_vector()
    yield [Solve(log.free_factor(), b, y)]
    log.back_substitutions += 1
    counts["log"] += 1
    b.destroy()
    return y


def _replay(dam, body, first: int, stop: int, h: float, theta: float, section: dict,
            counts: dict):
    """Step the dam alone (no impulse) through steps ``first``..``stop``−1, which were not
    stepped, recording its section (a re-contact needs its state); a generator of its
    solves, counted in ``counts["dam"]`` and the dam's counter."""
    for k in range(first, stop):
        b = body.rhs()
        y = dam.new_vector()
        yield [Solve(dam.factor, b, y)]
        dam.back_substitutions["dam_stage2"] += 1
        counts["dam"] += 1
        b.destroy()
        body.advance(y, h, theta)
        for q, v in dam.section_change(body.w).items():
            section[q][k] = v


def _log_values(log, vec, R, rigid) -> np.ndarray:
    """Front-end DOF values of a local-frame log vector, rotated to the dam's frame, plus
    the rigid part ``rigid`` (d,) on every node; node-major."""
    local = vec.array_r[log.front_dofs].reshape(-1, R.shape[0])
    return (local @ R.T + rigid[None, :]).reshape(-1)


def _outputs(s, dam, log, static, records, h, bl, R, heel, peak_principal, p_peak,
             offset_m, n) -> dict:
    m = contact_metrics(records, h, filter_window_s=force_filter_window_s(s))
    dp = R @ log.momentum_local(bl.omega)  # the rigid part V₀ keeps its momentum
    static_heel = static.section.sigma_heel_Pa
    return {
        "peak_force_N_per_m": m["peak_force"],
        "peak_force_filtered_N_per_m": m["peak_force_filtered"],
        "contact_duration_s": m["contact_duration_s"],
        "contact_start_s": m["contact_start_s"] if m["contact_start_s"] is not None else math.nan,
        "impulse_N_s_per_m": m["impulse"],
        "contact_episodes": m["episodes"],
        "log_momentum_change_N_s_per_m": float(dp[0]),
        "log_momentum_change_vertical_N_s_per_m": float(dp[-1]),
        "log_mass_kg_per_m": log.mass_kg_per_m,
        "log_velocity_after_m_s": float(s.log_speed_m_s * s.log_axis[0]
                                        + dp[0] / log.mass_kg_per_m),
        "log_rotation_rad": log.rotation_rad(bl.w),
        "heel_stress_static_Pa": static_heel,
        "heel_stress_impact_Pa": heel,
        "peak_tensile_stress_Pa": peak_principal if math.isfinite(peak_principal) else math.nan,
        "stress_offset_m": float(offset_m),
        "peak_contact_pressure_Pa": p_peak,
        "steps": int(n),
        "dt_s": float(h),
    }
