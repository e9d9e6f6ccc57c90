"""One impact scenario from a factored DamModel and LogModel: the bodies are coupled only
through contact (docs/architecture.md §7, per-body condensation).

The contact nodes are the placed log's front-end nodes (slaves, first) and the nodes of the
dam's face strip (masters, node–surface, paired once as stage 2 does). The kernel's F is
block-diagonal, [F̂_log (rotated), F̂_face], so ``_cpp.ImpactContact`` is used unchanged, and
each Moreau–Jean step (θ-scheme, dynamics.py) goes through the stepper for separately
condensed bodies (stepper.BodiesStepper):

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
from types import SimpleNamespace

import numpy as np

from .. import _cpp
from ..condensation import kernel_pairs
from ..pairing import pair_caps
from ..impact_output import contact_metrics
from ..postprocess import _nodal_contact
from ..stepper import BodiesStepper, CondensedBody
from ..surface_pairs import build_surface_pairs
from .log_model import rotation
from .stage2 import (MARGIN, approach_time_s, force_filter_window_s, log_crushing_strength_Pa,
                     response_duration_s)


def expected_contact_s(s, dam) -> float:
    """2L/c of the log along the face normal (x): its x-extent at the bar wave speed; the
    dam's own round trip (base width) is added as a bound as stage 2 does."""
    c_log = math.sqrt(s.wood.E_Pa / (s.wood.rho_kg_m3 * (1.0 + s.added_mass_coefficient)))
    a = s.log_axis
    extent = s.log_length_m * abs(a[0]) + s.log_diameter_m * abs(a[1])
    c_dam = math.sqrt(s.concrete.E_Pa / s.concrete.rho_kg_m3)
    return min(2.0 * extent / c_log, 2.0 * s.base_width_m / c_dam)


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


def run_impact(dam, log, s, static, offset_m: float = 1.0) -> dict:
    """The impact of scenario ``s`` (a DamScenario) from the static state ``static`` of
    ``dam`` at its water level, with ``log`` (the LogModel of its log). Returns the outputs
    (plain floats, see ScenarioEvaluator.evaluate)."""
    h, theta, d = dam.dt, dam.theta, 2
    R = rotation(s.log_pitch_deg)
    slave = log.placed_front(R, s.log_centre)
    pairs = build_surface_pairs([("node_to_surface", slave, dam.face)], d)
    m = pairs.m
    F = np.zeros((2 * pairs.x.shape[0],) * 2)
    n_log = 2 * m
    F[:n_log, :n_log] = log.W_front_global(R)
    F[n_log:, n_log:] = dam.W_face
    kernel = _cpp.ImpactContact(d, F, pairs.x, kernel_pairs(pairs), np.full(m, s.friction_mu),
                                0.0, h, theta, None, _cpp.SolverOptions())
    sigma_c = log_crushing_strength_Pa(s)
    if sigma_c is not None:
        pairs.crushing_strength = np.full(m, sigma_c)
        kernel.set_crushing(pair_caps(pairs))
    V0 = s.log_speed_m_s * np.asarray(s.log_axis, float)
    bd, bl = _Body(dam), _Body(log)
    u_face0 = static.u.x.array[dam.face_dofs]
    impact = np.array([0.0, s.log_front_point[-1]])
    cells = dam.stress_cells(impact, offset_m)
    # Long enough for the base: its moment peaks about half the dam's first period after
    # the impact, well after the contact has ended (stage2.response_duration_s).
    duration = max(approach_time_s(s) + MARGIN * expected_contact_s(s, dam),
                   response_duration_s(s))
    n = int(round(duration / h))
    records, heel, peak_principal, p_peak = [], -math.inf, -math.inf, 0.0
    solves0 = (dam.back_substitutions["dam_stage2"], log.back_substitutions)
    stepper = BodiesStepper(kernel, [
        CondensedBody("log", log.factor, log.front_dofs, log.new_vector, rotation=R,
                      counted=_log_solve_counter(log)),
        CondensedBody("dam", dam.factor, dam.face_dofs, dam.new_vector,
                      counted=_dam_solve_counter(dam))], expand_key="velocity_change_c")
    for i in range(n):
        t = i * h
        u_c = np.concatenate([_log_values(log, bl.w, R, V0 * t),
                              u_face0 + bd.w.array_r[dam.face_dofs]])
        v_c = np.concatenate([_log_values(log, bl.omega, R, V0),
                              bd.omega.array_r[dam.face_dofs]])
        rhs = [bl.rhs(), bd.rhs()]
        out, (dv_l, dv_d) = stepper.advance(rhs, where=f"time step {i + 1}", before=(u_c, v_c),
                                            free_shift=v_c)
        for b in rhs:
            if b is not None:
                b.destroy()
        bd.advance(dv_d, h, theta)
        bl.advance(dv_l, h, theta)
        active = int(np.asarray(out["active"], bool).sum())
        records.append(SimpleNamespace(t_s=(i + 1) * h, active=active,
                                       normal_force=float(out["normal_impulse"]) / h))
        if bd.pushed:
            heel = max(heel, dam.heel_stress_Pa(static, bd.w))
        if active > 0:
            peak_principal = max(peak_principal, dam.peak_principal_Pa(static, bd.w, cells))
            p_peak = max(p_peak, _peak_pressure(out, pairs, h))
    out = _outputs(s, dam, log, static, records, h, bl, R, heel, peak_principal, p_peak,
                   offset_m, n)
    out["dam_back_substitutions"] = dam.back_substitutions["dam_stage2"] - solves0[0]
    out["log_back_substitutions"] = log.back_substitutions - solves0[1]
    return out


def _log_values(log, vec, R, rigid) -> np.ndarray:
    """Front-end DOF values of a local-frame log vector, rotated to the dam's frame, plus
    the rigid part ``rigid`` (d,) on every node; node-major."""
    local = vec.array_r[log.front_dofs].reshape(-1, 2)
    return (local @ R.T + rigid[None, :]).reshape(-1)


def _peak_pressure(out: dict, pairs, h: float) -> float:
    """Largest contact pressure of the step (Pa): impulse / h over each contact node's
    tributary measure, slaves and masters, as ContactFields writes it."""
    inc = SimpleNamespace(lam=np.asarray(out["impulse"]) / h, states=np.asarray(out["states"]),
                          tangential=np.asarray(out["pair_tangential"]) / h)
    pressure, _, _ = _nodal_contact(inc, pairs)
    return float(pressure.max(initial=0.0))


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
        "log_momentum_change_vertical_N_s_per_m": float(dp[1]),
        "log_mass_kg_per_m": log.mass_kg_per_m,
        "log_velocity_after_m_s": float(s.log_speed_m_s * s.log_axis[0]
                                        + dp[0] / log.mass_kg_per_m),
        "log_rotation_rad": log.rotation_rad(bl.w),
        "heel_stress_static_Pa": static_heel,
        "heel_stress_impact_Pa": heel if math.isfinite(heel) else static_heel,
        "peak_tensile_stress_Pa": peak_principal if math.isfinite(peak_principal) else math.nan,
        "stress_offset_m": float(offset_m),
        "peak_contact_pressure_Pa": p_peak,
        "steps": int(n),
        "dt_s": float(h),
    }
