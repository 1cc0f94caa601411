//! A hydraulic jack (or winch) that carries the film's frame: the second FMU of the coupled
//! erection system (issue 21, `membrane_contact.ssp` packs it next to the film).
//!
//! The model, quasi-static over pseudo-time, one backward-Euler step per communication step:
//!
//! * a pump lowers the piston at `rate` while the pull `T = -force` stays below the valve's
//!   cracking force `crack · relief`; between it and `relief` the valve bypasses more and more
//!   of the flow (the speed falls linearly to 0: the jack stalls at `relief`); above `relief` the
//!   piston yields back, at most at `backRate`;
//! * the piston stays within `[-stroke, 0]`;
//! * a cylinder of `stiffness` links piston and frame: `dz = piston - force / stiffness`.
//!
//! With `force` reached at the end of the step, `piston₁ = clamp(piston₀ − h·v(T₁))`, so the
//! outputs depend on the inputs of the same step (direct feedthrough): the directional
//! derivatives ([`Jack::derivative`]) are those of the last step's end values with respect to
//! that step's end inputs, the step's start held. They are what a coupling master needs to
//! build the interface Jacobian. Where `v` has a kink (at `crack · relief`, `relief`, the
//! `backRate` floor, the stroke ends) they are one-sided: the branch of the current state.
//!
//! The FMI 2.0 Co-Simulation interface is the shared glue's (`fmu/glue`) over the model as
//! [`fmi`] describes it to the glue; this crate has no `unsafe` code of its own.

pub mod fmi;

use fmi_glue::description::{Causality, Dependencies, Description, VarType, Variability, Variable};
pub use fmi_glue::scalar::short;

/// Value references, in the order of `modelDescription.xml`.
pub mod vr {
    pub const FORCE: u32 = 0;
    pub const STIFFNESS: u32 = 1;
    pub const RELIEF: u32 = 2;
    pub const CRACK: u32 = 3;
    pub const RATE: u32 = 4;
    pub const BACK_RATE: u32 = 5;
    pub const STROKE: u32 = 6;
    pub const DZ: u32 = 7;
    pub const PISTON: u32 = 8;
    pub const SPEED: u32 = 9;
    /// Number of variables.
    pub const COUNT: usize = 10;
}

/// Variable names by value reference (the model description's).
pub const NAMES: [&str; vr::COUNT] = [
    "force",
    "stiffness",
    "relief",
    "crack",
    "rate",
    "backRate",
    "stroke",
    "dz",
    "piston",
    "speed",
];

/// The GUID of the model description (also its FMI 3.0 instantiation token).
pub const GUID: &str = "{6d1f4a52-3c0b-4e8e-9a57-2f1b8c4d7e21}";

/// The variable table and the rest of the model description: `modelDescription.xml` is
/// generated from it ([`model_description`]).
pub static DESCRIPTION: Description = Description {
    model_name: "HydraulicJack",
    model_identifier: "hydraulic_jack",
    token: GUID,
    description: "Hydraulic jack (or winch) that carries a frame: a pump lowers the piston at a constant rate, a relief valve limits the pull, a cylinder of finite stiffness links piston and frame. Quasi-static, backward Euler over each communication step.",
    generation_tool: "membrane-contact fmu/jack",
    can_get_and_set_fmu_state: true,
    can_serialize_fmu_state: false,
    provides_directional_derivative: true,
    units: &[
        ("m", "m=\"1\""),
        ("m/s", "m=\"1\" s=\"-1\""),
        ("N", "kg=\"1\" m=\"1\" s=\"-2\""),
        ("N/m", "kg=\"1\" s=\"-2\""),
        ("1", ""),
    ],
    log_categories: &[
        ("logStatusDiscard", ""),
        ("logStatusError", ""),
        ("logAll", ""),
    ],
    default_experiment: Some((0.0, 400.0, 5.0)),
    variables: &VARIABLES,
    outputs: &[
        Dependencies {
            output: vr::DZ,
            on: &[vr::FORCE, vr::STIFFNESS, vr::RELIEF],
        },
        Dependencies {
            output: vr::PISTON,
            on: &[vr::FORCE, vr::RELIEF],
        },
        Dependencies {
            output: vr::SPEED,
            on: &[vr::FORCE, vr::RELIEF],
        },
    ],
    initial_unknowns: &[
        Dependencies {
            output: vr::DZ,
            on: &[vr::FORCE, vr::STIFFNESS],
        },
        Dependencies {
            output: vr::PISTON,
            on: &[],
        },
        Dependencies {
            output: vr::SPEED,
            on: &[],
        },
    ],
};

/// One variable of the table: value reference `k`, its name and start from [`NAMES`] and
/// [`START`].
const fn variable(
    k: u32,
    causality: Causality,
    variability: Variability,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    let start = match causality {
        Causality::Output => None,
        _ => Some(START[k as usize]),
    };
    Variable {
        name: NAMES[k as usize],
        vr: k,
        var_type: VarType::Real,
        causality,
        variability,
        unit,
        start,
        description,
    }
}

use Causality::{Input, Output, Parameter};
use Variability::{Continuous, Fixed};

/// The jack's variables, by value reference.
const VARIABLES: [Variable; vr::COUNT] = [
    variable(
        vr::FORCE,
        Input,
        Continuous,
        "N",
        "force the jack applies to the frame along z, reached at the end of the step (connect the film's frame.Rz: the force the frame applies to the film); negative: the jack pulls the frame down",
    ),
    variable(
        vr::STIFFNESS,
        Input,
        Continuous,
        "N/m",
        "stiffness of the cylinder (oil column, rod, frame) between piston and frame, > 0",
    ),
    variable(
        vr::RELIEF,
        Input,
        Continuous,
        "N",
        "relief-valve setting as a pull on the frame, > 0: the piston stalls there and yields back above it",
    ),
    variable(
        vr::CRACK,
        Parameter,
        Fixed,
        "1",
        "the valve starts to open at crack * relief, in [0, 1)",
    ),
    variable(
        vr::RATE,
        Parameter,
        Fixed,
        "m/s",
        "lowering speed of the piston with the valve closed (pump flow / piston area), >= 0",
    ),
    variable(
        vr::BACK_RATE,
        Parameter,
        Fixed,
        "m/s",
        "fastest yielding back through the open valve, >= 0",
    ),
    variable(
        vr::STROKE,
        Parameter,
        Fixed,
        "m",
        "end of stroke: the piston stays within [-stroke, 0], >= 0",
    ),
    variable(
        vr::DZ,
        Output,
        Continuous,
        "m",
        "frame displacement along z: piston - force / stiffness (connect to the film's frame.dz)",
    ),
    variable(
        vr::PISTON,
        Output,
        Continuous,
        "m",
        "piston position along z (negative: lowered)",
    ),
    variable(
        vr::SPEED,
        Output,
        Continuous,
        "m/s",
        "lowering speed of the piston over the last step (negative: yielding back); 0 before the first step",
    ),
];

/// The FMI 2.0 `modelDescription.xml` of the jack, generated from [`DESCRIPTION`]
/// (`fmu/jack/modelDescription.xml` is this text, checked by a test).
pub fn model_description() -> String {
    DESCRIPTION.fmi2_xml()
}

/// The FMI 3.0 `modelDescription.xml` of the jack, generated from [`DESCRIPTION`]
/// (`fmu/jack/modelDescription3.xml` is this text, checked by a test).
pub fn model_description_fmi3() -> String {
    DESCRIPTION.fmi3_xml()
}

/// Default values (the model description's `start`), by value reference; outputs 0.
pub const START: [f64; vr::COUNT] = [0.0, 1.0e5, 600.0, 0.85, 5.0e-4, 5.0e-4, 0.15, 0.0, 0.0, 0.0];

/// The jack's whole state: every variable value, the piston at the start of the last step, the
/// last step size and the time. `Copy`, so an FMU state is a copy of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jack {
    /// Variable values by value reference.
    pub values: [f64; vr::COUNT],
    /// Piston position at the start of the last step (the state the step started from).
    pub piston_start: f64,
    /// Size of the last step (0 before the first).
    pub last_step: f64,
    /// Current time.
    pub time: f64,
}

impl Default for Jack {
    fn default() -> Self {
        let mut j = Jack {
            values: START,
            piston_start: 0.0,
            last_step: 0.0,
            time: 0.0,
        };
        j.update_outputs();
        j
    }
}

/// Why a value was refused: the variable's name and the rule, ready for the log.
pub fn check_value(vr: u32, value: f64) -> Result<(), String> {
    let name = NAMES
        .get(vr as usize)
        .ok_or_else(|| format!("unknown value reference {vr}"))?;
    let shown = short(value);
    if !value.is_finite() {
        return Err(format!("{name} = {shown}: values must be finite"));
    }
    let ok = match vr {
        vr::STIFFNESS | vr::RELIEF => value > 0.0,
        vr::CRACK => (0.0..1.0).contains(&value),
        vr::RATE | vr::BACK_RATE | vr::STROKE => value >= 0.0,
        _ => true,
    };
    if ok {
        Ok(())
    } else {
        let rule = match vr {
            vr::STIFFNESS | vr::RELIEF => "must be > 0",
            vr::CRACK => "must lie in [0, 1)",
            _ => "must be >= 0",
        };
        Err(format!("{name} = {shown} {rule}"))
    }
}

impl Jack {
    fn v(&self, k: u32) -> f64 {
        self.values[k as usize]
    }

    /// Lowering speed of the piston under the pull `pull` (> 0 lowering, < 0 yielding back)
    /// and its derivatives with respect to the pull and to `relief`. Branches: pumping for
    /// `pull <= crack · relief`, the valve's band up to the `backRate` floor (included), the
    /// floor beyond: at a kink, the derivatives of the branch of the smaller pull (one-sided:
    /// from the side of the larger `force`).
    pub fn velocity(&self, pull: f64) -> (f64, f64, f64) {
        let (rate, relief, crack, back) = (
            self.v(vr::RATE),
            self.v(vr::RELIEF),
            self.v(vr::CRACK),
            self.v(vr::BACK_RATE),
        );
        let band = relief * (1.0 - crack);
        if pull <= crack * relief {
            return (rate, 0.0, 0.0);
        }
        let v = rate * (relief - pull) / band;
        if v < -back {
            return (-back, 0.0, 0.0);
        }
        // d/dR [(R - T) / (R (1 - c))] = T / (R² (1 - c))
        (v, -rate / band, rate * pull / (relief * band))
    }

    /// The piston reached from `piston_start` over `h` under the current inputs, and whether the
    /// stroke's ends hold it (then it does not depend on the inputs).
    fn piston_after(&self, h: f64) -> (f64, bool) {
        let (v, _, _) = self.velocity(-self.v(vr::FORCE));
        let trial = self.piston_start - h * v;
        let stroke = self.v(vr::STROKE);
        if trial > 0.0 {
            (0.0, true)
        } else if trial < -stroke {
            (-stroke, true)
        } else {
            (trial, false)
        }
    }

    fn update_outputs(&mut self) {
        let h = self.last_step;
        let (piston, _) = self.piston_after(h);
        self.values[vr::PISTON as usize] = piston;
        self.values[vr::DZ as usize] = piston - self.v(vr::FORCE) / self.v(vr::STIFFNESS);
        self.values[vr::SPEED as usize] = if h > 0.0 {
            (self.piston_start - piston) / h
        } else {
            0.0
        };
    }

    /// Recomputes the outputs of the current time from the inputs (initialization: no step yet).
    /// Refused, the jack unchanged, when an output would not be finite ([`Self::finite`]).
    pub fn initialize(&mut self) -> Result<(), String> {
        let mut next = *self;
        next.piston_start = next.v(vr::PISTON);
        next.last_step = 0.0;
        next.update_outputs();
        *self = next.finite()?;
        Ok(())
    }

    /// One communication step of size `h > 0` to the inputs as they are now. Refused, the jack
    /// unchanged (the last good state: outputs, piston and time), when an output or the time
    /// would not be finite ([`Self::finite`]): never a step that ends in an overflow.
    pub fn step(&mut self, h: f64) -> Result<(), String> {
        let mut next = *self;
        next.piston_start = next.v(vr::PISTON);
        next.last_step = h;
        next.update_outputs();
        next.time += h;
        *self = next
            .finite()
            .map_err(|e| format!("{e}; the jack stays at t = {}", short(self.time)))?;
        Ok(())
    }

    /// `self` when every value and the time are finite; else why not: the first one that is
    /// not, with the inputs and parameters it came from.
    pub fn finite(self) -> Result<Self, String> {
        let bad = (self.values.iter().zip(NAMES))
            .map(|(&v, name)| (name, v))
            .chain([("time", self.time)])
            .find(|(_, v)| !v.is_finite());
        match bad {
            None => Ok(self),
            Some((name, v)) => {
                let inputs: Vec<String> = (0..vr::DZ as usize)
                    .map(|k| format!("{} = {}", NAMES[k], short(self.values[k])))
                    .collect();
                Err(format!(
                    "{name} would be {} ({}, step size {}): the result overflows",
                    short(v),
                    inputs.join(", "),
                    short(self.last_step)
                ))
            }
        }
    }

    /// Derivative of output `unknown` with respect to input `known` at the end of the last
    /// step (its start held), or `None` when `unknown` is not an output or `known` not an input.
    pub fn derivative(&self, unknown: u32, known: u32) -> Option<f64> {
        if !matches!(known, vr::FORCE | vr::STIFFNESS | vr::RELIEF) {
            return None;
        }
        let h = self.last_step;
        let (_, held) = self.piston_after(h);
        let (_, dv_dpull, dv_drelief) = self.velocity(-self.v(vr::FORCE));
        // piston = piston_start - h v(-force, relief)
        let dpiston = if held {
            0.0
        } else {
            match known {
                vr::FORCE => h * dv_dpull,
                vr::RELIEF => -h * dv_drelief,
                _ => 0.0,
            }
        };
        let k = self.v(vr::STIFFNESS);
        match unknown {
            vr::PISTON => Some(dpiston),
            vr::SPEED => Some(if h > 0.0 { -dpiston / h } else { 0.0 }),
            vr::DZ => Some(
                dpiston
                    + match known {
                        vr::FORCE => -1.0 / k,
                        vr::STIFFNESS => self.v(vr::FORCE) / (k * k),
                        _ => 0.0,
                    },
            ),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stepped(force: f64, relief: f64, h: f64) -> Jack {
        let mut j = Jack::default();
        j.values[vr::PISTON as usize] = -0.05;
        j.values[vr::FORCE as usize] = force;
        j.values[vr::RELIEF as usize] = relief;
        j.step(h).unwrap();
        j
    }

    #[test]
    fn derivatives_match_central_differences_on_every_branch() {
        // pumping, valve opening, yielding back at the floor, and the near-linear spring
        for (force, relief) in [
            (-100.0, 600.0),
            (-550.0, 600.0),
            (-2000.0, 600.0),
            (-580.0, 600.0),
        ] {
            let j = stepped(force, relief, 5.0);
            for known in [vr::FORCE, vr::STIFFNESS, vr::RELIEF] {
                let x = j.values[known as usize];
                let d = 1e-6 * x.abs().max(1.0);
                let mut plus = stepped(force, relief, 5.0);
                let mut minus = plus;
                plus.values = {
                    let mut v = j.values;
                    v[known as usize] = x + d;
                    v
                };
                minus.values[known as usize] = x - d;
                for s in [&mut plus, &mut minus] {
                    s.values[vr::PISTON as usize] = -0.05;
                    s.step(5.0).unwrap();
                }
                for unknown in [vr::DZ, vr::PISTON, vr::SPEED] {
                    let fd = (plus.values[unknown as usize] - minus.values[unknown as usize])
                        / (2.0 * d);
                    let exact = j.derivative(unknown, known).unwrap();
                    assert!(
                        (fd - exact).abs() <= 1e-6 * exact.abs().max(1e-9) + 1e-12,
                        "d{}/d{} at force {force}: exact {exact}, central difference {fd}",
                        NAMES[unknown as usize],
                        NAMES[known as usize]
                    );
                }
            }
        }
    }

    #[test]
    fn derivative_at_a_valve_kink_is_the_one_sided_slope_from_the_larger_force() {
        // binary-exact settings, so that the pulls below lie exactly on the kinks
        let (h, relief, crack, rate) = (0.01, 600.0, 0.75, 0.5);
        let band = relief * (1.0 - crack);
        let piston = |force: f64| {
            let mut j = Jack::default();
            for (k, v) in [(vr::CRACK, crack), (vr::RATE, rate), (vr::BACK_RATE, rate)] {
                j.values[k as usize] = v;
            }
            j.values[vr::PISTON as usize] = -0.05;
            j.values[vr::FORCE as usize] = force;
            j.step(h).unwrap();
            (
                j.values[vr::PISTON as usize],
                j.derivative(vr::PISTON, vr::FORCE).unwrap(),
            )
        };
        // the valve cracking open (450 N), and the floor where the piston yields back at
        // backRate (750 N)
        for pull in [crack * relief, relief + band] {
            let (at, exact) = piston(-pull);
            let d = 1e-6;
            let above = (piston(-pull + d).0 - at) / d;
            let below = (at - piston(-pull - d).0) / d;
            assert!(
                (exact - above).abs() <= 1e-6 * above.abs().max(1e-9),
                "pull {pull}: {exact} vs {above}"
            );
            assert!(
                (exact - below).abs() > 0.5 * h * rate / band,
                "pull {pull}: {exact} = {below}"
            );
        }
    }

    #[test]
    fn a_step_whose_output_overflows_is_refused_naming_it_and_keeps_the_last_state() {
        let mut j = Jack::default();
        j.values[vr::STIFFNESS as usize] = 1e-10;
        j.initialize().unwrap();
        j.step(1.0).unwrap();
        let good = j;
        j.values[vr::FORCE as usize] = 1e308;
        let e = j.step(1.0).unwrap_err();
        for part in [
            "dz would be -inf",
            "force = 1e308",
            "stiffness = 1e-10",
            "the jack stays at t = 1",
        ] {
            assert!(e.contains(part), "'{e}' lacks '{part}'");
        }
        assert_eq!(j.values[vr::DZ as usize], good.values[vr::DZ as usize]);
        assert_eq!((j.time, j.piston_start), (good.time, good.piston_start));
        // initialization recomputes the outputs too: refused alike, the jack unchanged
        let before = j;
        assert!(j.initialize().unwrap_err().contains("dz would be -inf"));
        assert_eq!(j, before);
    }

    #[test]
    fn refused_values_are_shown_short_whatever_their_magnitude() {
        assert_eq!(
            check_value(vr::STIFFNESS, -1e308).unwrap_err(),
            "stiffness = -1e308 must be > 0"
        );
        assert_eq!(
            check_value(vr::RELIEF, -1e-300).unwrap_err(),
            "relief = -1e-300 must be > 0"
        );
        assert_eq!(
            check_value(vr::FORCE, f64::INFINITY).unwrap_err(),
            "force = inf: values must be finite"
        );
        assert_eq!(
            check_value(vr::STIFFNESS, -1.0).unwrap_err(),
            "stiffness = -1 must be > 0"
        );
    }

    #[test]
    fn relief_valve_stalls_the_piston_at_the_relief_force() {
        let j = stepped(-600.0, 600.0, 5.0);
        assert_eq!(j.values[vr::SPEED as usize], 0.0);
        assert_eq!(j.values[vr::PISTON as usize], -0.05);
        let pumping = stepped(-100.0, 600.0, 5.0);
        assert!((pumping.values[vr::SPEED as usize] - 5.0e-4).abs() < 1e-15);
    }

    #[test]
    fn derivatives_refuse_what_is_not_an_output_or_not_an_input() {
        let j = Jack::default();
        assert_eq!(j.derivative(vr::FORCE, vr::FORCE), None);
        assert_eq!(j.derivative(vr::DZ, vr::DZ), None);
        assert_eq!(j.derivative(vr::DZ, vr::CRACK), None);
    }
}
