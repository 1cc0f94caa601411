//! Numbers the stress update runs on: `f64` and dual numbers (forward-mode derivatives, so that
//! the algorithmic tangent is the exact derivative of the update), and 2×2 symmetric tensors
//! with the matrix logarithm and exponential written smoothly through equal eigenvalues.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Anything the stress update runs on: `f64` and the dual numbers.
pub(super) trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn c(x: f64) -> Self;
    fn v(self) -> f64;
    fn sqrt(self) -> Self;
    fn ln(self) -> Self;
    fn map(self, f: f64, df: f64) -> Self;
}

impl Real for f64 {
    fn c(x: f64) -> Self {
        x
    }
    fn v(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn map(self, f: f64, _df: f64) -> Self {
        f
    }
}

/// A number with its gradient with respect to the three Green strains (the reference update
/// the tests compare against).
#[cfg(test)]
#[derive(Clone, Copy, Debug)]
pub(super) struct Dual {
    pub(super) v: f64,
    pub(super) d: [f64; 3],
}

/// A number with its gradient with respect to the two invariants `(s, r²)` of `Y` (module doc
/// of `plasticity`: the tangent is assembled in closed form from these).
#[derive(Clone, Copy, Debug)]
pub(super) struct Dual2 {
    pub(super) v: f64,
    pub(super) d: [f64; 2],
}

/// A number with one derivative (the return's scalar equations).
#[derive(Clone, Copy, Debug)]
pub(super) struct Dual1 {
    pub(super) v: f64,
    pub(super) d: f64,
}

macro_rules! dual_ops {
    ($t:ty, $zip:expr, $scale:expr) => {
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Add for $t {
            type Output = Self;
            fn add(self, o: Self) -> Self {
                Self {
                    v: self.v + o.v,
                    d: $zip(self.d, o.d, 1.0, 1.0),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Sub for $t {
            type Output = Self;
            fn sub(self, o: Self) -> Self {
                Self {
                    v: self.v - o.v,
                    d: $zip(self.d, o.d, 1.0, -1.0),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Mul for $t {
            type Output = Self;
            fn mul(self, o: Self) -> Self {
                Self {
                    v: self.v * o.v,
                    d: $zip(self.d, o.d, o.v, self.v),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Div for $t {
            type Output = Self;
            fn div(self, o: Self) -> Self {
                let inv = 1.0 / o.v;
                Self {
                    v: self.v / o.v,
                    d: $zip(self.d, o.d, inv, -self.v * inv * inv),
                }
            }
        }
        impl Neg for $t {
            type Output = Self;
            fn neg(self) -> Self {
                Self {
                    v: -self.v,
                    d: $scale(self.d, -1.0),
                }
            }
        }
        impl Real for $t {
            fn c(x: f64) -> Self {
                Self {
                    v: x,
                    d: $scale(Default::default(), 0.0),
                }
            }
            fn v(self) -> f64 {
                self.v
            }
            fn sqrt(self) -> Self {
                let r = self.v.sqrt();
                self.map(r, 0.5 / r)
            }
            fn ln(self) -> Self {
                self.map(self.v.ln(), 1.0 / self.v)
            }
            fn map(self, f: f64, df: f64) -> Self {
                Self {
                    v: f,
                    d: $scale(self.d, df),
                }
            }
        }
    };
}

#[cfg(test)]
dual_ops!(
    Dual,
    |a: [f64; 3], b: [f64; 3], x: f64, y: f64| [
        a[0] * x + b[0] * y,
        a[1] * x + b[1] * y,
        a[2] * x + b[2] * y
    ],
    |a: [f64; 3], s: f64| [a[0] * s, a[1] * s, a[2] * s]
);
dual_ops!(
    Dual2,
    |a: [f64; 2], b: [f64; 2], x: f64, y: f64| [a[0] * x + b[0] * y, a[1] * x + b[1] * y],
    |a: [f64; 2], s: f64| [a[0] * s, a[1] * s]
);
dual_ops!(
    Dual1,
    |a: f64, b: f64, x: f64, y: f64| a * x + b * y,
    |a: f64, s: f64| a * s
);

/// `x²`.
pub(super) fn sq<T: Real>(x: T) -> T {
    x * x
}

/// `atanh(√w)/√w`, smooth in `w ∈ [0, 1)` (series near 0).
pub(super) fn atanh_over<T: Real>(w: T) -> T {
    let wv = w.v();
    if wv < 1e-6 {
        T::c(1.0) + w * (T::c(1.0 / 3.0) + w * (T::c(0.2) + w * T::c(1.0 / 7.0)))
    } else {
        let z = wv.sqrt();
        let f = z.atanh() / z;
        // d/dw [atanh(z)/z] = (1/(1 − w) − atanh(z)/z) / (2w).
        w.map(f, (1.0 / (1.0 - wv) - f) / (2.0 * wv))
    }
}

/// A symmetric 2×2 tensor.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sym2<T> {
    pub(super) xx: T,
    pub(super) yy: T,
    pub(super) xy: T,
}

impl<T: Real> Add for Sym2<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            xx: self.xx + o.xx,
            yy: self.yy + o.yy,
            xy: self.xy + o.xy,
        }
    }
}

impl<T: Real> Sym2<T> {
    pub(super) fn identity(s: T) -> Self {
        Self {
            xx: s,
            yy: s,
            xy: T::c(0.0),
        }
    }
    pub(super) fn mean(&self) -> T {
        (self.xx + self.yy) * T::c(0.5)
    }
    pub(super) fn dev(&self) -> Self {
        let m = self.mean();
        Self {
            xx: self.xx - m,
            yy: self.yy - m,
            xy: self.xy,
        }
    }
    pub(super) fn scale(&self, s: f64) -> Self {
        self.scale_t(T::c(s))
    }
    pub(super) fn scale_t(&self, s: T) -> Self {
        Self {
            xx: self.xx * s,
            yy: self.yy * s,
            xy: self.xy * s,
        }
    }
    #[cfg(test)]
    pub(super) fn sub(&self, o: Self) -> Self {
        Self {
            xx: self.xx - o.xx,
            yy: self.yy - o.yy,
            xy: self.xy - o.xy,
        }
    }
    #[cfg(test)]
    pub(super) fn frob2(&self) -> T {
        self.xx * self.xx + self.yy * self.yy + self.xy * self.xy * T::c(2.0)
    }
    #[cfg(test)]
    pub(super) fn value(&self) -> Sym2<f64> {
        Sym2 {
            xx: self.xx.v(),
            yy: self.yy.v(),
            xy: self.xy.v(),
        }
    }
    /// `M A Mᵀ` for a plain 2×2 `M`.
    pub(super) fn congruence(&self, m: &[[f64; 2]; 2]) -> Self {
        let a = [[self.xx, self.xy], [self.xy, self.yy]];
        let entry = |i: usize, j: usize| {
            let mut s = T::c(0.0);
            for (k, ak) in a.iter().enumerate() {
                for (l, akl) in ak.iter().enumerate() {
                    s = s + *akl * T::c(m[i][k] * m[j][l]);
                }
            }
            s
        };
        Self {
            xx: entry(0, 0),
            yy: entry(1, 1),
            xy: entry(0, 1),
        }
    }
    #[cfg(test)]
    /// `A B` of two commuting symmetric tensors (symmetric; off-diagonal averaged).
    pub(super) fn commuting_product(&self, b: &Self) -> Self {
        Self {
            xx: self.xx * b.xx + self.xy * b.xy,
            yy: self.xy * b.xy + self.yy * b.yy,
            xy: (self.xx * b.xy + self.xy * b.yy + self.xy * b.xx + self.yy * b.xy) * T::c(0.5),
        }
    }
}

/// `exp A` of a symmetric 2×2: `e^m (cosh ρ I + sinh ρ/ρ dev A)`, `ρ² = −det(dev A)`.
pub(super) fn exp_sym(a: Sym2<f64>) -> Sym2<f64> {
    let (m, dev) = (a.mean(), a.dev());
    let rho2 = dev.xx * dev.xx + dev.xy * dev.xy;
    let (cosh, sinhc) = if rho2 < 1e-8 {
        (
            1.0 + rho2 / 2.0 + rho2 * rho2 / 24.0,
            1.0 + rho2 / 6.0 + rho2 * rho2 / 120.0,
        )
    } else {
        let rho = rho2.sqrt();
        (rho.cosh(), rho.sinh() / rho)
    };
    Sym2::identity(m.exp() * cosh) + dev.scale(m.exp() * sinhc)
}
