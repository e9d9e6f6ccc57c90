"""The base section's response to the face impulses, by the adjoint: after the contact the
dam need not be stepped (docs/dam.md, "Response functions").

The dam is linear and starts at rest relative to its static state, so each time step of the
θ-scheme is x⁺ = A x + B P with x = (w, ω) and P the face impulse of the step:

    Δω = Ŵ⁻¹ (−hK (w + hθ ω) + Sᵀ P),   ω⁺ = ω + Δω,   w⁺ = w + hω + hθ Δω.

A quantity q of the base section is linear in w, Δq = g·w, so after step n

    Δq_n = Σ_{k<n} G_{n−1−k} · P_k,   G_j = Bᵀ (Aᵀ)ʲ (g, 0).

G is computed backwards, for each output: with λ = (a, b) starting at (g, 0),

    z = Ŵ⁻¹ (hθ a + b),   G_j = S z,   λ ← (a − hKz,  ha + b − h²θ Kz)

(Ŵ and K symmetric): one back-substitution per lag and output, not one forward run per face
DOF. Only the normal force and the moment about the centre are tabulated: the heel and toe
stresses are their linear combinations −N/(Bw) ± 6M/(wB²). Stress components, not
principal stresses, which are not linear.

The outputs go backwards side by side, their right-hand sides solved together where the
factor takes several (``solve_many``), with the dam's plain factor of Ŵ where it has one
(DamModel.response_factor): a full solve on the Schur factor that the contact steps use is
a condensation, a product with the face's dense F* and an expansion, 87 ms against about
15 ms at a 51,309-DOF block with 7,410 face DOFs.
"""
from __future__ import annotations

import numpy as np

TABULATED = ("normal_force_N", "moment_centre_Nm")
"""The section quantities whose response functions are tabulated."""


class ResponseFunctions:
    """G_j for j < ``n`` of the tabulated quantities of ``dam`` (a DamModel), extended on
    demand (``ensure(n)``) from the adjoint state where the last extension stopped. Each lag
    costs one back-substitution per quantity with Ŵ's factor (DamModel.response_factor),
    counted in ``dam.back_substitutions["dam_response"]``."""

    def __init__(self, dam):
        self.dam = dam
        self.G = {q: np.zeros((0, dam.face_dofs.size)) for q in TABULATED}
        self._state = {q: None for q in TABULATED}
        dam.back_substitutions.setdefault("dam_response", 0)

    @property
    def lags(self) -> int:
        return self.G[TABULATED[0]].shape[0]

    def ensure(self, n: int) -> None:
        """Tabulate at least ``n`` lags."""
        if n <= self.lags:
            return
        if any(self._state[q] is None for q in TABULATED):
            # Tabulated elsewhere (a model file) without the adjoint state to go on from:
            # start again from lag 0.
            self.G = self._backward(n, fresh=True)
            return
        more = self._backward(n - self.lags)
        self.G = {q: np.vstack([self.G[q], more[q]]) for q in TABULATED}

    def saved(self) -> dict:
        """The tabulated G and the adjoint state to go on from, as arrays (a model file)."""
        out = {}
        for q in TABULATED:
            out[f"G_{q}"] = self.G[q]
            if self._state[q] is not None:
                out[f"adjoint_a_{q}"] = self._state[q][0].array_r.copy()
                out[f"adjoint_b_{q}"] = self._state[q][1].array_r.copy()
        return out

    def restore(self, arrays: dict) -> None:
        """Take the G and adjoint state of :meth:`saved` (extension goes on from them)."""
        for q in TABULATED:
            self.G[q] = np.asarray(arrays[f"G_{q}"])
            if f"adjoint_a_{q}" in arrays:
                a, b = self.dam.new_vector(), self.dam.new_vector()
                a.array[:] = arrays[f"adjoint_a_{q}"]
                b.array[:] = arrays[f"adjoint_b_{q}"]
                self._state[q] = (a, b)

    def _backward(self, count: int, fresh: bool = False) -> dict:
        """The next ``count`` lags of every tabulated quantity (from lag 0 if ``fresh``)."""
        dam = self.dam
        h, theta = dam.dt, dam.theta
        if fresh:
            self._state = {q: None for q in TABULATED}
        for q in TABULATED:
            if self._state[q] is None:
                a, b = dam.new_vector(), dam.new_vector()
                a.array[:] = dam.section_gradients[q]
                self._state[q] = (a, b)
        factor = dam.response_factor()
        together = hasattr(factor, "solve_many")
        z, Kz = dam.new_vector(), dam.new_vector()
        out = {q: np.empty((count, dam.face_dofs.size)) for q in TABULATED}
        B = np.empty((z.getSize(), len(TABULATED)), order="F")
        rhs = None if together else dam.new_vector()
        for j in range(count):
            for c, q in enumerate(TABULATED):
                a, b = self._state[q]
                B[:, c] = h * theta * a.array_r + b.array_r
            if together:
                Z = factor.solve_many(B)
            else:
                Z = np.empty_like(B)
                for c in range(B.shape[1]):
                    rhs.array[:] = B[:, c]
                    factor.solve(rhs, z)
                    Z[:, c] = z.array_r
            dam.back_substitutions["dam_response"] += len(TABULATED)
            for c, q in enumerate(TABULATED):
                a, b = self._state[q]
                z.array[:] = Z[:, c]
                out[q][j] = Z[dam.face_dofs, c]
                dam.K.mult(z, Kz)
                a_old = a.array_r.copy()
                a.array[:] = a_old - h * Kz.array_r
                b.array[:] = h * a_old + b.array_r - h * h * theta * Kz.array_r
        for v in (rhs, z, Kz):
            if v is not None:
                v.destroy()
        return out

    def convolve(self, impulses: np.ndarray, n: int) -> dict:
        """{quantity: Δq after steps 1..n} (arrays of n) for the face impulses
        ``impulses`` (k × face DOFs: step k's P_k; the steps after them impulse-free), the
        heel and toe stresses included."""
        self.ensure(n)
        P = np.asarray(impulses, float)
        out = {}
        for q in TABULATED:
            C = self.G[q][:n] @ P.T       # C[j, k] = G_j · P_k
            y = np.zeros(n)
            for k in range(min(P.shape[0], n)):
                y[k:] += C[: n - k, k]      # Δq after step i (index i) takes G_{i−k} · P_k
            out[q] = y
        B, width = self.dam.base.base_width_m, self.dam.section_width_m
        N, M = out["normal_force_N"], out["moment_centre_Nm"]
        out["sigma_heel_Pa"] = -N / (B * width) + 6.0 * M / (width * B * B)
        out["sigma_toe_Pa"] = -N / (B * width) - 6.0 * M / (width * B * B)
        return out
