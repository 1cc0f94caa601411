"""An independent axisymmetric membrane solver for the bubble-inflation test (issue 20):
a clamped circular film inflated by a follower pressure, elasto-plastic, large strains.

Written for ``test_bubble.py`` from the textbook equations, with nothing of the product called:

* **Meridian.** The material radius ``R ∈ [0, a]`` is cut into ``n`` equal two-node conical
  frusta; the unknowns are the current radius ``r`` and height ``z`` of the nodes (pole on the
  axis, ``r = 0``; rim clamped, ``r = a``, ``z = 0``). Each frustum has one material point at
  its middle: meridional stretch ``λ1 = L/ΔR`` (``L`` the current frustum length), hoop stretch
  ``λ2 = r_m/R_m``. By symmetry these are principal and their axes never turn, so Hencky strains
  ``εi = ln λi`` split additively into elastic and plastic parts.
* **Material.** Plane stress, Hencky elasticity ``τ1 = E/(1 − ν²)(εe1 + ν εe2)`` (Kirchhoff),
  von Mises ``σeq = √(τ1² − τ1τ2 + τ2²)`` against the hardening table ``σy(ε̄p)`` (piecewise linear,
  last slope continued), associated flow ``Δεpi = Δγ ∂σeq/∂τi``, ``Δε̄p = Δγ``, solved by backward
  Euler in principal stresses: with ``p = (τ1 + τ2)/2``, ``q = (τ1 − τ2)/2`` and ``s = σy(ε̄p + Δγ)``,
  ``p = p_tr/(1 + E Δγ/(2(1 − ν) s))``, ``q = q_tr/(1 + 3 G Δγ/s)`` and ``p² + 3q² = s²`` (one
  scalar equation for ``Δγ``, Newton kept in a bracket). The plastic thickness strain is
  ``εp33 = −(εp1 + εp2)`` (isochoric flow), the elastic one ``εe33 = −ν(τ1 + τ2)/E`` (``τ33 = 0``).
* **Cut-backs.** The whole film reaches yield at nearly the same height, and Newton can stall
  there; a height increment whose Newton fails is halved. The Jacobian's difference step is
  1e-10 of the radius, so that few columns straddle an element's yield kink.
* **Equilibrium** in the current configuration: the membrane forces are the Cauchy stresses
  ``σi = τi/J`` (``J = exp(εe1 + εe2 + εe33)``) times the current thickness
  ``t = t0 exp(εe33 + εp33)``; their virtual work over the current frustum area ``2π r_m L``
  balances the pressure's, ``p δV`` (``V`` the volume under the meridian: a follower pressure
  on a film with a held rim is conservative).
* **Control.** The pole height ``h`` is prescribed and ``p`` is an unknown (so a pressure maximum
  would not stop it); each height step is an increment whose plastic history is committed when
  Newton converges. The Jacobian is by finite differences, three colours per coordinate (a node
  only meets its neighbours).
"""

from __future__ import annotations

import math

import numpy as np


class Hardening:
    """Piecewise-linear flow stress ``σy(ε̄p)`` from rows (ε̄p, σy in Pa); the last slope continues."""

    def __init__(self, rows, scale=1.0):
        rows = np.asarray(rows, dtype=float)
        self.strain = rows[:, 0]
        self.stress = rows[:, 1] * scale
        if len(rows) > 1:
            self.slope = np.diff(self.stress) / np.diff(self.strain)
        else:
            self.slope = np.zeros(1)

    def _segment(self, ep):
        return np.clip(np.searchsorted(self.strain, ep, side="right") - 1, 0, len(self.slope) - 1)

    def __call__(self, ep):
        k = self._segment(ep)
        return self.stress[k] + self.slope[k] * (ep - self.strain[k])

    def hardening_modulus(self, ep):
        """``dσy/dε̄p`` (the right slope at a row)."""
        return self.slope[self._segment(ep)]


class Film:
    """Elastic constants, initial thickness and hardening of the membrane."""

    def __init__(self, youngs_modulus, poisson_ratio, thickness, hardening, plastic_thinning=True):
        self.E, self.nu, self.t0 = youngs_modulus, poisson_ratio, thickness
        self.hardening = hardening
        self.G = youngs_modulus / (2 * (1 + poisson_ratio))
        self.Ebar = youngs_modulus / (1 - poisson_ratio)
        #: False drops the plastic thickness strain (only to check that the test sees it).
        self.plastic_thinning = plastic_thinning

    def stress(self, e1, e2, history):
        """Kirchhoff stresses ``τ1, τ2`` and the trial history at log strains ``e1, e2``
        (arrays), from the committed ``history = (εp1, εp2, ε̄p)``."""
        ep1, ep2, ebar = history
        et1, et2 = e1 - ep1, e2 - ep2
        c = self.E / (1 - self.nu ** 2)
        t1, t2 = c * (et1 + self.nu * et2), c * (et2 + self.nu * et1)
        sy = self.hardening(ebar)
        seq = np.sqrt(t1 * t1 - t1 * t2 + t2 * t2)
        plastic = seq > sy * (1 + 1e-13)
        if not plastic.any():
            return t1, t2, history
        p_tr, q_tr = 0.5 * (t1 + t2), 0.5 * (t1 - t2)

        # F(Δγ) = p² + 3q² − s², decreasing from F(0) > 0: Newton kept inside a bracket
        a, b = self.Ebar / 2, 3 * self.G
        lo, hi = np.zeros_like(seq), np.full_like(seq, np.inf)
        dg = np.zeros_like(seq)
        for _ in range(100):
            s = self.hardening(ebar + dg)
            slope = self.hardening.hardening_modulus(ebar + dg)
            u = dg / s
            du = (s - dg * slope) / (s * s)
            p, q = p_tr / (1 + a * u), q_tr / (1 + b * u)
            f = p * p + 3 * q * q - s * s
            df = -2 * p * p * a * du / (1 + a * u) - 6 * q * q * b * du / (1 + b * u) - 2 * s * slope
            lo, hi = np.where(f > 0, dg, lo), np.where(f > 0, hi, dg)
            new = dg - f / df
            inside = (new > lo) & (new < hi)
            new = np.where(inside, new, np.where(np.isfinite(hi), 0.5 * (lo + hi), 2 * dg + (seq - sy) / b))
            done = np.abs(new - dg) <= 1e-15 * np.maximum(dg, 1e-300)
            dg = np.where(plastic, new, 0.0)
            if done[plastic].all():
                break
        s = self.hardening(ebar + dg)
        p, q = p_tr / (1 + a * dg / s), q_tr / (1 + b * dg / s)
        tau1, tau2 = np.where(plastic, p + q, t1), np.where(plastic, p - q, t2)
        n1 = (2 * tau1 - tau2) / (2 * s)
        n2 = (2 * tau2 - tau1) / (2 * s)
        return tau1, tau2, (ep1 + dg * n1, ep2 + dg * n2, ebar + dg)

    def membrane_forces(self, e1, e2, history):
        """Forces per unit current length ``σi t`` (N/m), the current thickness and the trial
        history."""
        tau1, tau2, trial = self.stress(e1, e2, history)
        ep1, ep2, _ = trial
        eps_e33 = -self.nu * (tau1 + tau2) / self.E
        eps_p33 = -(ep1 + ep2) if self.plastic_thinning else 0.0
        volume = np.exp((e1 - ep1) + (e2 - ep2) + eps_e33)  # elastic = total: isochoric flow
        thickness = self.t0 * np.exp(eps_e33 + eps_p33)
        return tau1 / volume * thickness, tau2 / volume * thickness, thickness, trial


class Bubble:
    """The clamped disc of radius ``a`` on ``n`` frusta (module doc)."""

    def __init__(self, film: Film, radius: float, n: int = 100):
        self.film, self.a, self.n = film, radius, n
        self.R = np.linspace(0.0, radius, n + 1)
        self.dR = np.diff(self.R)
        self.Rm = 0.5 * (self.R[:-1] + self.R[1:])
        zeros = np.zeros(n)
        self.history = (zeros, zeros.copy(), zeros.copy())

    # unknowns: r[1:n], z[1:n], p (z[0] = h prescribed)
    def _unpack(self, x, h):
        n = self.n
        r = np.concatenate([[0.0], x[: n - 1], [self.a]])
        z = np.concatenate([[h], x[n - 1: 2 * n - 2], [0.0]])
        return r, z, x[-1]

    def residual(self, x, h, with_state=False):
        r, z, p = self._unpack(x, h)
        dr, dz = np.diff(r), np.diff(z)
        length = np.hypot(dr, dz)
        rm = 0.5 * (r[:-1] + r[1:])
        e1, e2 = np.log(length / self.dR), np.log(rm / self.Rm)
        n1, n2, thickness, trial = self.film.membrane_forces(e1, e2, self.history)
        area = 2 * math.pi * rm * length
        w1, w2 = area * n1, area * n2
        fr, fz = np.zeros(self.n + 1), np.zeros(self.n + 1)
        # δε1 = (dr δ(Δr) + dz δ(Δz))/L², δε2 = (δr_a + δr_b)/(2 r_m)
        g1r, g1z = w1 * dr / length ** 2, w1 * dz / length ** 2
        g2 = w2 * 0.5 / rm
        np.add.at(fr, np.arange(self.n), -g1r + g2)
        np.add.at(fr, np.arange(1, self.n + 1), g1r + g2)
        np.add.at(fz, np.arange(self.n), -g1z)
        np.add.at(fz, np.arange(1, self.n + 1), g1z)
        # p δV, V = −π/3 Σ (z_b − z_a)(r_a² + r_a r_b + r_b²)
        ra, rb = r[:-1], r[1:]
        quad = ra * ra + ra * rb + rb * rb
        vr, vz = np.zeros(self.n + 1), np.zeros(self.n + 1)
        np.add.at(vz, np.arange(self.n), math.pi / 3 * quad)
        np.add.at(vz, np.arange(1, self.n + 1), -math.pi / 3 * quad)
        np.add.at(vr, np.arange(self.n), -math.pi / 3 * dz * (2 * ra + rb))
        np.add.at(vr, np.arange(1, self.n + 1), -math.pi / 3 * dz * (ra + 2 * rb))
        res = np.concatenate([(fr - p * vr)[1: self.n], (fz - p * vz)[: self.n]])
        if with_state:
            return res, trial, thickness, (e1, e2)
        return res

    def _jacobian(self, x, h, res0):
        n = self.n
        jac = np.zeros((len(x), len(x)))
        step = 1e-10 * self.a  # small: a step across an element's yield kink spoils its column
        for block in (0, 1):  # r[1:n] are x[0:n-1] (node i ↦ x[i-1]); z[1:n] are x[n-1:2n-2]
            for colour in range(3):
                nodes = np.arange(1, n)
                nodes = nodes[nodes % 3 == colour]
                cols = nodes - 1 + block * (n - 1)
                xp = x.copy()
                xp[cols] += step
                diff = (self.residual(xp, h) - res0) / step
                # residual rows of node j: r row j-1 (j ≥ 1), z row n-1+j (j ≥ 0)
                for node, col in zip(nodes, cols):
                    for j in (node - 1, node, node + 1):
                        if 1 <= j <= n - 1:
                            jac[j - 1, col] = diff[j - 1]
                        if 0 <= j <= n - 1:
                            jac[n - 1 + j, col] = diff[n - 1 + j]
        # pressure column: −∂V/∂x, exact
        xp = x.copy()
        xp[-1] = 0.0
        jac[:, -1] = (res0 - self.residual(xp, h)) / x[-1] if x[-1] != 0 else self._dv(x, h)
        return jac

    def _dv(self, x, h):
        x1, x0 = x.copy(), x.copy()
        x1[-1], x0[-1] = 1.0, 0.0
        return self.residual(x1, h) - self.residual(x0, h)

    def _solve(self, x, h, tolerance, max_iterations):
        """Newton with backtracking on the residual norm from ``x``; ``None`` if it fails."""
        scale = self.film.hardening(0.0) * self.film.t0 * self.a
        res = self.residual(x, h)
        for _ in range(max_iterations):
            if np.max(np.abs(res)) < tolerance * scale:
                return x
            dx = np.linalg.solve(self._jacobian(x, h, res), -res)
            norm, step = np.linalg.norm(res), 1.0
            while True:
                trial = self.residual(x + step * dx, h)
                if np.linalg.norm(trial) < norm:
                    break
                step *= 0.5
                if step < 1e-3:
                    return None
            x, res = x + step * dx, trial
        return None

    def inflate(self, heights, max_increment=math.inf, tolerance=1e-10, max_iterations=25):
        """Raises the pole to each of ``heights`` (increasing) in increments no larger than
        ``max_increment`` nor the gap between two of them, halved when Newton fails; the history
        is committed after each increment. Returns the pressures, the smallest thickness and the
        largest ε̄p at ``heights``."""
        n = self.n
        flat = np.concatenate([self.R[1:n], np.zeros(n - 1), [0.0]])
        previous = [(0.0, flat)]  # the last two converged increments: the predictor
        x, h_now = flat, 0.0
        pressures, min_thickness, max_strain = [], [], []
        for target in heights:
            nominal = min(target - h_now, max_increment)
            dh = nominal
            while h_now < target:
                h = min(h_now + dh, target)
                if len(previous) == 1:  # from flat: a parabolic cap
                    guess = flat.copy()
                    guess[n - 1: 2 * n - 2] = h * (1 - (self.R[1:n] / self.a) ** 2)
                else:
                    (h1, x1), (h2, x2) = previous
                    guess = x2 + (x2 - x1) * (h - h2) / (h2 - h1)
                solved = self._solve(guess, h, tolerance, max_iterations)
                if solved is None:
                    dh *= 0.5
                    if dh < 1e-6 * self.a:
                        raise RuntimeError(f"the axisymmetric reference did not converge at h = {h}")
                    continue
                x, h_now = solved, h
                self.history = self.residual(x, h, with_state=True)[1]
                previous = (previous + [(h, x.copy())])[-2:]
                dh = min(2 * dh, nominal)
            _, trial, thickness, _ = self.residual(x, h_now, with_state=True)
            pressures.append(x[-1])
            min_thickness.append(thickness.min())
            max_strain.append(trial[2].max())
        return np.array(pressures), np.array(min_thickness), np.array(max_strain)
