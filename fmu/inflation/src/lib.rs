//! An ETFE cushion's inflation unit: the second FMU of the cushion system (issue 43 item 5),
//! coupled to the film FMU's chamber (`<chamber>.pressure → pressure`,
//! `massFlow → <chamber>.massFlow`).
//!
//! The unit, as real units run:
//!
//! * a **fan** with the quadratic curve `Δp(Q) = p₀ (1 − (Q/Q_max)²)`: against the cushion's
//!   gauge pressure `p` it delivers `Q_fan = Q_max √(1 − p/p₀)` ([`fan_flow`]);
//! * a **non-return valve** behind it: no flow back out of the cushion when the fan is off or
//!   the cushion's pressure reaches the fan's shut-off pressure `p₀` (`Q_fan = 0` there);
//! * a **leakage orifice** from the cushion to the outside, `Q = C_d A √(2|p|/ρ)`, out of the
//!   cushion while `p > 0`, in while `p < 0` ([`leak_flow`]);
//! * an on/off **pressure switch with hysteresis**: its contact closes at `p ≤ switchOn` and
//!   opens at `p ≥ switchOff` ([`demand`]), and the fan follows its contact after
//!   `switchDelay` seconds (the motor's start/stop timer, which keeps the fan from cycling at
//!   every flicker of the pressure);
//! * a **snow mode**, as real units have (the roof's controller, or a snow sensor, sets it
//!   while snow lies on the cushion): while the Boolean input `snowMode` is true the switch
//!   works in the snow band `snowSwitchOn`/`snowSwitchOff` (default 400/550 Pa) instead, so
//!   that the cushion is held stiffer against the snow. The contact keeps its state when the
//!   band changes and sees the pressure against the new band at the next step: switched on at
//!   300 Pa it closes (300 ≤ 400) and the fan starts after its delay; switched off at 500 Pa it
//!   opens (500 ≥ 350).
//!
//! **Contract of a step.** The cushion's pressure is held at its input value over the
//! co-simulation step (the film FMU steps with the unit's flow of the same step: a Jacobi or
//! Gauss–Seidel exchange of one value). Within the step the unit integrates exactly in sub-steps
//! split where its fan toggles (the switch's delay running out); `massFlow` is the net mass
//! flow into the cushion *averaged over the step*, so that the film, which adds
//! `massFlow · h`, holds exactly the air the unit delivered. `duty` is the fraction of the last
//! step the fan ran, `dutyTotal` the fraction since the start.
//!
//! The FMI 2.0 and 3.0 Co-Simulation interfaces are the shared glue's (`fmu/glue`) over the
//! model as [`fmi`] describes it; this crate has no `unsafe` code of its own.

pub mod fmi;

use fmi_glue::description::{Causality, Dependencies, Description, VarType, Variability, Variable};
pub use fmi_glue::scalar::short;

/// Value references, in the order of `modelDescription.xml`.
pub mod vr {
    /// Input: the cushion's gauge pressure (Pa).
    pub const PRESSURE: u32 = 0;
    /// Parameter: the fan's shut-off pressure `p₀` (Pa).
    pub const FAN_PRESSURE: u32 = 1;
    /// Parameter: the fan's free delivery `Q_max` (m³/s).
    pub const FAN_FLOW_MAX: u32 = 2;
    /// Parameter: the leakage orifice's area `A` (m²).
    pub const LEAK_AREA: u32 = 3;
    /// Parameter: the orifice's discharge coefficient `C_d`.
    pub const LEAK_COEFFICIENT: u32 = 4;
    /// Parameter: the air's density `ρ` (kg/m³).
    pub const AIR_DENSITY: u32 = 5;
    /// Parameter: the switch's contact closes at or below it (Pa).
    pub const SWITCH_ON: u32 = 6;
    /// Parameter: the switch's contact opens at or above it (Pa).
    pub const SWITCH_OFF: u32 = 7;
    /// Parameter: the fan follows the contact this long after it changed (s).
    pub const SWITCH_DELAY: u32 = 8;
    /// Output: net mass flow into the cushion, the step's average (kg/s).
    pub const MASS_FLOW: u32 = 9;
    /// Output: 1 while the fan runs at the end of the step.
    pub const FAN_ON: u32 = 10;
    /// Output: the fraction of the last step the fan ran.
    pub const DUTY: u32 = 11;
    /// Output: the fraction of the time since the start the fan ran.
    pub const DUTY_TOTAL: u32 = 12;
    /// Output: the fan's delivery, the step's average (m³/s).
    pub const FAN_FLOW: u32 = 13;
    /// Output: the leak out of the cushion, the step's average (m³/s).
    pub const LEAK_FLOW: u32 = 14;
    /// Input (Boolean, held as 0 or 1): the switch works in the snow band.
    pub const SNOW_MODE: u32 = 15;
    /// Parameter: in snow mode the contact closes at or below it (Pa).
    pub const SNOW_SWITCH_ON: u32 = 16;
    /// Parameter: in snow mode the contact opens at or above it (Pa).
    pub const SNOW_SWITCH_OFF: u32 = 17;
    /// Number of variables.
    pub const COUNT: usize = 18;
    /// Number of variables before the snow mode (a serialized state of that version holds
    /// their values alone).
    pub const FORMER_COUNT: usize = 15;
}

/// Variable names by value reference (the model description's).
pub const NAMES: [&str; vr::COUNT] = [
    "pressure",
    "fanPressure",
    "fanFlowMax",
    "leakArea",
    "leakCoefficient",
    "airDensity",
    "switchOn",
    "switchOff",
    "switchDelay",
    "massFlow",
    "fanOn",
    "duty",
    "dutyTotal",
    "fanFlow",
    "leakFlow",
    "snowMode",
    "snowSwitchOn",
    "snowSwitchOff",
];

/// The GUID of the model description (also its FMI 3.0 instantiation token).
pub const GUID: &str = "{23e2e275-59ab-4657-9fef-1bb35aa2f008}";

/// Default values (the model description's `start`), by value reference; outputs 0. A unit
/// for a cushion of about 2 m span held at 250–350 Pa, at 400–550 Pa in snow mode (off at
/// the start): a fan of 800 Pa shut-off and 1 L/s free delivery, 10 mm² of leaks at a discharge
/// coefficient of 0.6, air at 1.2 kg/m³, a 1.5 s start/stop timer.
pub const START: [f64; vr::COUNT] = [
    300.0, 800.0, 1.0e-3, 1.0e-5, 0.6, 1.2, 250.0, 350.0, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    400.0, 550.0,
];

/// The variable table and the rest of the model description: `modelDescription.xml` and
/// `modelDescription3.xml` are generated from it.
pub static DESCRIPTION: Description = Description {
    model_name: "InflationUnit",
    model_identifier: "inflation_unit",
    token: GUID,
    description: "Inflation unit of an ETFE cushion: a fan with a quadratic curve behind a non-return valve, a leakage orifice to the outside, an on/off pressure switch with hysteresis, a snow mode that raises its band, and a start/stop delay. The cushion's pressure is held over each step; the net mass flow into the cushion is the step's average.",
    generation_tool: "membrane-contact fmu/inflation",
    can_get_and_set_fmu_state: true,
    can_serialize_fmu_state: true,
    provides_directional_derivative: false,
    units: &[
        ("Pa", "kg=\"1\" m=\"-1\" s=\"-2\""),
        ("m3/s", "m=\"3\" s=\"-1\""),
        ("m2", "m=\"2\""),
        ("kg/m3", "kg=\"1\" m=\"-3\""),
        ("kg/s", "kg=\"1\" s=\"-1\""),
        ("s", "s=\"1\""),
        ("1", ""),
    ],
    log_categories: &[
        ("logStatusDiscard", ""),
        ("logStatusError", ""),
        ("logAll", ""),
    ],
    default_experiment: Some((0.0, 300.0, 1.0)),
    variables: &VARIABLES,
    outputs: &OUTPUTS,
    initial_unknowns: &OUTPUTS,
};

/// Every output depends on the cushion's pressure of the same step (direct feedthrough) and on
/// the snow mode (the switch's band).
const OUTPUTS: [Dependencies; 6] = [
    depends(vr::MASS_FLOW),
    depends(vr::FAN_ON),
    depends(vr::DUTY),
    depends(vr::DUTY_TOTAL),
    depends(vr::FAN_FLOW),
    depends(vr::LEAK_FLOW),
];

const fn depends(output: u32) -> Dependencies {
    Dependencies {
        output,
        on: &[vr::PRESSURE, vr::SNOW_MODE],
    }
}

/// One variable of the table: value reference `k`, its name and start from [`NAMES`] and
/// [`START`].
const fn variable(
    k: u32,
    causality: Causality,
    unit: &'static str,
    text: &'static str,
) -> Variable {
    let (variability, start) = match causality {
        Causality::Output => (Variability::Continuous, None),
        Causality::Input => (Variability::Continuous, Some(START[k as usize])),
        Causality::Parameter => (Variability::Fixed, Some(START[k as usize])),
    };
    Variable {
        name: NAMES[k as usize],
        vr: k,
        var_type: VarType::Real,
        causality,
        variability,
        unit,
        start,
        description: text,
    }
}

/// The Boolean input of value reference `k` (held as 0 or 1), its start from [`START`].
const fn boolean_input(k: u32, text: &'static str) -> Variable {
    Variable {
        name: NAMES[k as usize],
        vr: k,
        var_type: VarType::Boolean,
        causality: Causality::Input,
        variability: Variability::Discrete,
        unit: "",
        start: Some(START[k as usize]),
        description: text,
    }
}

use Causality::{Input, Output, Parameter};

/// The unit's variables, by value reference.
const VARIABLES: [Variable; vr::COUNT] = [
    variable(
        vr::PRESSURE,
        Input,
        "Pa",
        "gauge pressure of the cushion's air, held over the step (connect the film's <chamber>.pressure)",
    ),
    variable(
        vr::FAN_PRESSURE,
        Parameter,
        "Pa",
        "fan's shut-off pressure p0 (no flow against it), > 0",
    ),
    variable(
        vr::FAN_FLOW_MAX,
        Parameter,
        "m3/s",
        "fan's free delivery Qmax (against no pressure), >= 0",
    ),
    variable(
        vr::LEAK_AREA,
        Parameter,
        "m2",
        "area of the leakage orifice from the cushion to the outside, >= 0",
    ),
    variable(
        vr::LEAK_COEFFICIENT,
        Parameter,
        "1",
        "discharge coefficient Cd of the leakage orifice, in [0, 1]",
    ),
    variable(
        vr::AIR_DENSITY,
        Parameter,
        "kg/m3",
        "density of the air, > 0",
    ),
    variable(
        vr::SWITCH_ON,
        Parameter,
        "Pa",
        "the pressure switch calls for the fan at a cushion pressure <= switchOn (below switchOff)",
    ),
    variable(
        vr::SWITCH_OFF,
        Parameter,
        "Pa",
        "the pressure switch stops the fan at a cushion pressure >= switchOff (above switchOn)",
    ),
    variable(
        vr::SWITCH_DELAY,
        Parameter,
        "s",
        "start/stop delay: the fan follows the switch's contact this long after it changed, >= 0",
    ),
    variable(
        vr::MASS_FLOW,
        Output,
        "kg/s",
        "net air mass flow into the cushion (fan less leakage), averaged over the last step, 0 before the first (connect to the film's <chamber>.massFlow)",
    ),
    variable(
        vr::FAN_ON,
        Output,
        "1",
        "1 while the fan runs at the end of the last step, else 0",
    ),
    variable(
        vr::DUTY,
        Output,
        "1",
        "fraction of the last step the fan ran (0 before the first step)",
    ),
    variable(
        vr::DUTY_TOTAL,
        Output,
        "1",
        "fraction of the time since the start the fan ran (0 before the first step)",
    ),
    variable(
        vr::FAN_FLOW,
        Output,
        "m3/s",
        "volume flow the fan delivered through its non-return valve, averaged over the last step (0 before the first)",
    ),
    variable(
        vr::LEAK_FLOW,
        Output,
        "m3/s",
        "volume flow out through the leakage orifice (negative: in) over the last step (0 before the first)",
    ),
    boolean_input(
        vr::SNOW_MODE,
        "snow mode: while true the switch works in the snow band snowSwitchOn/snowSwitchOff instead of switchOn/switchOff (set it while snow lies on the cushion)",
    ),
    variable(
        vr::SNOW_SWITCH_ON,
        Parameter,
        "Pa",
        "in snow mode the pressure switch calls for the fan at a cushion pressure <= snowSwitchOn (below snowSwitchOff)",
    ),
    variable(
        vr::SNOW_SWITCH_OFF,
        Parameter,
        "Pa",
        "in snow mode the pressure switch stops the fan at a cushion pressure >= snowSwitchOff (above snowSwitchOn)",
    ),
];

/// The fan's delivery `Q_max √(1 − p/p₀)` (m³/s) through its non-return valve against the
/// gauge pressure `p`: 0 from the shut-off pressure `p₀` up (the valve closes; no back flow).
pub fn fan_flow(p: f64, p0: f64, q_max: f64) -> f64 {
    if p >= p0 {
        0.0
    } else {
        q_max * (1.0 - p / p0).sqrt()
    }
}

/// The orifice's volume flow `C_d A √(2|p|/ρ)` (m³/s) out of the cushion at gauge pressure
/// `p` (negative, into it, where `p < 0`).
pub fn leak_flow(p: f64, cd: f64, area: f64, rho: f64) -> f64 {
    (cd * area * (2.0 * p.abs() / rho).sqrt()).copysign(p)
}

/// The switch's contact after seeing `p`: closed (the fan called for) at `p ≤ on`, open at
/// `p ≥ off`, as it was (`closed`) in between.
pub fn demand(closed: bool, p: f64, on: f64, off: f64) -> bool {
    if p <= on {
        true
    } else if p >= off {
        false
    } else {
        closed
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
    let rule = match vr {
        vr::FAN_PRESSURE | vr::AIR_DENSITY if value <= 0.0 => "must be > 0",
        vr::FAN_FLOW_MAX | vr::LEAK_AREA | vr::SWITCH_DELAY if value < 0.0 => "must be >= 0",
        vr::LEAK_COEFFICIENT if !(0.0..=1.0).contains(&value) => "must lie in [0, 1]",
        vr::SNOW_MODE if value != 0.0 && value != 1.0 => "must be 0 or 1 (false or true)",
        _ => return Ok(()),
    };
    Err(format!("{name} = {shown} {rule}"))
}

/// The unit's whole state: every variable value, the switch's contact, the delay's timer, the
/// fan's running time and the time stepped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    /// Variable values by value reference.
    pub values: [f64; vr::COUNT],
    /// Whether the switch's contact calls for the fan.
    pub contact: bool,
    /// How long the contact has differed from the fan's state (s).
    pub timer: f64,
    /// Time the fan ran since the start (s).
    pub on_time: f64,
    /// Time stepped since the start (s).
    pub run_time: f64,
    /// Current time.
    pub time: f64,
}

/// Numbers of a serialized [`Unit`]: the values, then contact, timer, on time, run time, time.
const NUMBERS: usize = vr::COUNT + 5;
/// Numbers of a state serialized before the snow mode: the values of the first
/// [`vr::FORMER_COUNT`] variables, then the same five.
const FORMER_NUMBERS: usize = vr::FORMER_COUNT + 5;

impl Default for Unit {
    fn default() -> Self {
        let mut unit = Unit {
            values: START,
            contact: false,
            timer: 0.0,
            on_time: 0.0,
            run_time: 0.0,
            time: 0.0,
        };
        unit.initialize().expect("the start values are valid");
        unit
    }
}

impl Unit {
    fn v(&self, k: u32) -> f64 {
        self.values[k as usize]
    }

    fn fan_is_on(&self) -> bool {
        self.v(vr::FAN_ON) != 0.0
    }

    /// The switch bands' rule across two parameters: `switchOn < switchOff`, and
    /// `snowSwitchOn < snowSwitchOff`.
    fn check_band(&self) -> Result<(), String> {
        for (on, off) in [
            (vr::SWITCH_ON, vr::SWITCH_OFF),
            (vr::SNOW_SWITCH_ON, vr::SNOW_SWITCH_OFF),
        ] {
            let (p_on, p_off) = (self.v(on), self.v(off));
            if p_on >= p_off {
                return Err(format!(
                    "{} = {} Pa must lie below {} = {} Pa (in initialization mode set both in \
                     one call)",
                    NAMES[on as usize],
                    short(p_on),
                    NAMES[off as usize],
                    short(p_off)
                ));
            }
        }
        Ok(())
    }

    /// The switch's band `(on, off)` now: the snow band in snow mode.
    pub fn band(&self) -> (f64, f64) {
        if self.v(vr::SNOW_MODE) != 0.0 {
            (self.v(vr::SNOW_SWITCH_ON), self.v(vr::SNOW_SWITCH_OFF))
        } else {
            (self.v(vr::SWITCH_ON), self.v(vr::SWITCH_OFF))
        }
    }

    /// The flows at the held pressure with the fan running a fraction `duty` of the time:
    /// fan's (m³/s), leak's (m³/s), net mass flow in (kg/s).
    fn flows(&self, duty: f64) -> (f64, f64, f64) {
        let p = self.v(vr::PRESSURE);
        let fan = duty * fan_flow(p, self.v(vr::FAN_PRESSURE), self.v(vr::FAN_FLOW_MAX));
        let leak = leak_flow(
            p,
            self.v(vr::LEAK_COEFFICIENT),
            self.v(vr::LEAK_AREA),
            self.v(vr::AIR_DENSITY),
        );
        (fan, leak, self.v(vr::AIR_DENSITY) * (fan - leak))
    }

    /// The step's averages with the fan running a fraction `duty` of it; all 0 before the
    /// first step (no step to average over: the film, whose `massFlow` input starts at 0,
    /// agrees with the unit whatever the importer transfers first).
    fn set_outputs(&mut self, duty: f64) {
        let (fan, leak, mass) = if self.run_time > 0.0 {
            self.flows(duty)
        } else {
            (0.0, 0.0, 0.0)
        };
        self.values[vr::MASS_FLOW as usize] = mass;
        self.values[vr::DUTY as usize] = duty;
        self.values[vr::FAN_FLOW as usize] = fan;
        self.values[vr::LEAK_FLOW as usize] = leak;
        self.values[vr::DUTY_TOTAL as usize] = if self.run_time > 0.0 {
            self.on_time / self.run_time
        } else {
            0.0
        };
    }

    /// The unit at power-on with the inputs and parameters as they are: the fan runs iff the
    /// pressure is at or below the band's on pressure ([`Self::band`]: its contact closed); the
    /// averaged outputs 0. Refused, the unit unchanged, where a band is reversed.
    pub fn initialize(&mut self) -> Result<(), String> {
        self.check_band()?;
        let mut next = *self;
        let (on, off) = next.band();
        next.contact = demand(false, next.v(vr::PRESSURE), on, off);
        next.values[vr::FAN_ON as usize] = f64::from(u8::from(next.contact));
        (next.timer, next.on_time, next.run_time) = (0.0, 0.0, 0.0);
        next.set_outputs(0.0);
        *self = next.finite()?;
        Ok(())
    }

    /// The time into a step of size `h` at which the fan toggles (the delay running out), if
    /// it does within the step; the contact already updated.
    pub fn toggle_time(&self, h: f64) -> Option<f64> {
        if self.contact == self.fan_is_on() {
            return None;
        }
        let at = (self.v(vr::SWITCH_DELAY) - self.timer).max(0.0);
        (at < h).then_some(at)
    }

    /// One communication step of size `h > 0` with the pressure held at its input: the contact
    /// sees the pressure, the fan follows it after the delay (a sub-step boundary where it
    /// toggles), the outputs are the step's averages. Refused, the unit unchanged, where an
    /// output or the time would not be finite.
    pub fn step(&mut self, h: f64) -> Result<(), String> {
        let mut next = *self;
        let (on, off) = next.band();
        next.contact = demand(next.contact, next.v(vr::PRESSURE), on, off);
        if next.contact == next.fan_is_on() {
            next.timer = 0.0;
        }
        // The two sub-steps [0, t) and [t, h): the fan's state before and after its toggle.
        let was_on = next.fan_is_on();
        let on_time = match next.toggle_time(h) {
            Some(t) => {
                next.values[vr::FAN_ON as usize] = f64::from(u8::from(!was_on));
                next.timer = 0.0;
                if was_on { t } else { h - t }
            }
            None => {
                if next.contact != was_on {
                    next.timer += h;
                }
                if was_on { h } else { 0.0 }
            }
        };
        next.on_time += on_time;
        next.run_time += h;
        next.time += h;
        next.set_outputs(on_time / h);
        *self = next
            .finite()
            .map_err(|e| format!("{e}; the unit stays at t = {}", short(self.time)))?;
        Ok(())
    }

    /// `self` when every value and the time are finite; else why not.
    pub fn finite(self) -> Result<Self, String> {
        let bad = (self.values.iter().zip(NAMES))
            .map(|(&v, name)| (name, v))
            .chain([("time", self.time), ("timer", self.timer)])
            .find(|(_, v)| !v.is_finite());
        match bad {
            None => Ok(self),
            Some((name, v)) => Err(format!(
                "{name} would be {} (pressure = {} Pa): the result overflows",
                short(v),
                short(self.v(vr::PRESSURE))
            )),
        }
    }

    /// The state as numbers (serialized FMU states): [`NUMBERS`] of them.
    pub fn to_numbers(&self) -> Vec<f64> {
        let mut n = self.values.to_vec();
        n.extend([
            f64::from(u8::from(self.contact)),
            self.timer,
            self.on_time,
            self.run_time,
            self.time,
        ]);
        n
    }

    /// The unit of [`Self::to_numbers`]' numbers, checked: their count, every value by its
    /// variable's rule, the switch bands, flags 0 or 1, times finite and not negative. A state
    /// serialized before the snow mode ([`FORMER_NUMBERS`]) reads with snow mode off and the
    /// snow band at its defaults.
    pub fn from_numbers(n: &[f64]) -> Result<Self, String> {
        let upgraded;
        let n = match n.len() {
            NUMBERS => n,
            FORMER_NUMBERS => {
                let (values, rest) = n.split_at(vr::FORMER_COUNT);
                upgraded = [values, &START[vr::FORMER_COUNT..], rest].concat();
                &upgraded
            }
            other => {
                return Err(format!(
                    "a serialized state of the unit has {NUMBERS} numbers ({FORMER_NUMBERS} \
                     before the snow mode), not {other}"
                ));
            }
        };
        for (k, &x) in n[..vr::COUNT].iter().enumerate() {
            check_value(k as u32, x).map_err(|e| format!("serialized state: {e}"))?;
        }
        let flag = |x: f64| x == 0.0 || x == 1.0;
        let times = &n[vr::COUNT + 1..];
        if !flag(n[vr::FAN_ON as usize]) || !flag(n[vr::COUNT]) {
            return Err("serialized state: fanOn and the contact must be 0 or 1".into());
        }
        if !times.iter().all(|t| t.is_finite()) || times[..3].iter().any(|&t| t < 0.0) {
            return Err("serialized state: its times must be finite and not negative".into());
        }
        let unit = Unit {
            values: n[..vr::COUNT].try_into().expect("COUNT values"),
            contact: n[vr::COUNT] == 1.0,
            timer: times[0],
            on_time: times[1],
            run_time: times[2],
            time: times[3],
        };
        unit.check_band()?;
        unit.finite()
    }
}

#[cfg(test)]
mod tests;
