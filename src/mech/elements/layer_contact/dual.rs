//! Forward-mode dual numbers over the twelve coordinates of a node-to-triangle pair (the slave
//! node's three, then the master triangle's nine): a value and its gradient. The pair's force is
//! written once in them and its exact (consistent) tangent is the gradient part, as in
//! automatic differentiation of element codes (Korelc & Wriggers, *Automation of Finite Element
//! Methods*, 2016, ch. 2).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Number of independent variables of a pair.
pub const N: usize = 12;

/// A value with its gradient with respect to the pair's twelve coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f64,
    /// Its derivatives.
    pub d: [f64; N],
}

impl Dual {
    /// A constant (zero gradient).
    pub fn constant(v: f64) -> Self {
        Self { v, d: [0.0; N] }
    }

    /// The independent variable number `i` at value `v`.
    pub fn variable(v: f64, i: usize) -> Self {
        let mut d = [0.0; N];
        d[i] = 1.0;
        Self { v, d }
    }

    /// The square root (of a positive value).
    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.scaled_with(s, 0.5 / s)
    }

    /// `(value, self.d · slope)`: a function of `self` given its value and derivative.
    fn scaled_with(self, v: f64, slope: f64) -> Self {
        Self {
            v,
            d: self.d.map(|x| x * slope),
        }
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual {
            v: self.v + o.v,
            d: std::array::from_fn(|i| self.d[i] + o.d[i]),
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual {
            v: self.v - o.v,
            d: std::array::from_fn(|i| self.d[i] - o.d[i]),
        }
    }
}

impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        self.scaled_with(-self.v, -1.0)
    }
}

// The product and quotient rules mix the operations.
#[allow(clippy::suspicious_arithmetic_impl)]
impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self.v * o.v,
            d: std::array::from_fn(|i| self.d[i] * o.v + self.v * o.d[i]),
        }
    }
}

impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, s: f64) -> Dual {
        self.scaled_with(self.v * s, s)
    }
}

#[allow(clippy::suspicious_arithmetic_impl)]
impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let q = self.v / o.v;
        Dual {
            v: q,
            d: std::array::from_fn(|i| (self.d[i] - q * o.d[i]) / o.v),
        }
    }
}

/// A 3-vector of duals.
pub type V3 = [Dual; 3];

/// `a + b`.
pub fn add(a: &V3, b: &V3) -> V3 {
    std::array::from_fn(|i| a[i] + b[i])
}

/// `a − b`.
pub fn sub(a: &V3, b: &V3) -> V3 {
    std::array::from_fn(|i| a[i] - b[i])
}

/// `s a`.
pub fn scale(a: &V3, s: Dual) -> V3 {
    a.map(|x| x * s)
}

/// `a · b`.
pub fn dot(a: &V3, b: &V3) -> Dual {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
pub fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_of_products_quotients_and_roots_are_the_calculus_rules() {
        let x = Dual::variable(2.0, 0);
        let y = Dual::variable(3.0, 1);
        let f = (x * y + x * 2.0) / (y - x).sqrt();
        // f = (xy + 2x)/√(y−x) at (2, 3): ∂f/∂x = (y+2)/1 + (xy+2x)/2 = 5 + 5 = 10,
        // ∂f/∂y = x − (xy+2x)/2 = 2 − 5 = −3.
        assert!((f.v - 10.0).abs() < 1e-12);
        assert!((f.d[0] - 10.0).abs() < 1e-12, "{}", f.d[0]);
        assert!((f.d[1] + 3.0).abs() < 1e-12, "{}", f.d[1]);
        assert_eq!((-f).d[1], 3.0);
    }
}
