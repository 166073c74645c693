//! Conversions of raw test channels into physical quantities in SI units: strain-gauge
//! bridges, accelerometers given by their sensitivity, and units.
//!
//! **Bridges.** With the amplified bridge output `V`, the amplifier gain `G` and the
//! excitation `V_ex`, the bridge ratio is `V_r = V / (G V_ex)`; with the gauge factor `GF`
//! (`dR / R = GF epsilon`) and Poisson's ratio `nu`, the strain `epsilon` of a Wheatstone
//! bridge with equal arms is, by configuration (the tables of Campbell Scientific's
//! `StrainCalc` and National Instruments' strain-gauge notes; derived from the bridge's
//! divider ratios `R1 / (R1 + R2) - R4 / (R3 + R4)`; `V_r > 0` in tension, a bridge wired
//! the other way gives `-V_r`: negate the gain):
//!
//! | configuration | active gauges | `epsilon` |
//! |---|---|---|
//! | quarter | one, axial | `4 V_r / (GF (1 - 2 V_r))` |
//! | half, Poisson | one axial, one transverse (adjacent arms) | `4 V_r / (GF ((1 + nu) - 2 V_r (1 - nu)))` |
//! | half, bending | two, `+epsilon` and `-epsilon` (adjacent arms) | `2 V_r / GF` |
//! | half, axial | two axial on opposite faces (opposite arms; bending cancels) | `2 V_r / (GF (1 - V_r))` |
//! | full, bending | four, two `+epsilon`, two `-epsilon` | `V_r / GF` |
//! | full, bending with Poisson | `+epsilon`, `-epsilon` and `+-nu epsilon` | `2 V_r / (GF (1 + nu))` |
//! | full, Poisson (axial) | two axial, two transverse | `2 V_r / (GF ((1 + nu) - V_r (1 - nu)))` |
//!
//! The quarter, half-Poisson, half-axial and full-Poisson forms are exact (the bridge's own
//! non-linearity included); the others are linear in `V_r` exactly.
//!
//! **Accelerometers.** A sensitivity `S` in mV/g and an amplifier gain `G`:
//! `a = V / (G S 10^-3) g_n` in m/s^2, `g_n = 9.80665 m/s^2` (standard gravity, ISO 80000-3).
//!
//! **Units.** A channel recorded in a [`Unit`] is multiplied by its exact factor to SI.

use serde::{Deserialize, Serialize};

/// Standard gravity `g_n` (m/s^2), ISO 80000-3.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// How the gauges of a Wheatstone bridge are placed (see the module table).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Bridge {
    /// One active gauge along the strain.
    Quarter,
    /// One gauge along the strain and one across it, in adjacent arms.
    HalfPoisson {
        /// Poisson's ratio of the surface.
        poisson: f64,
    },
    /// Two gauges of equal and opposite strain (bending), in adjacent arms.
    HalfBending,
    /// Two axial gauges on opposite faces of a bar, in opposite arms: their mean strain,
    /// bending cancelled (the usual Kolsky bar set-up).
    HalfAxial,
    /// Four gauges, two of `+epsilon`, two of `-epsilon` (bending).
    FullBending,
    /// Four gauges in bending, `+epsilon`, `-epsilon`, `+nu epsilon`, `-nu epsilon`.
    FullBendingPoisson {
        /// Poisson's ratio.
        poisson: f64,
    },
    /// Four gauges on an axially loaded member: two along the strain, two across it.
    FullPoisson {
        /// Poisson's ratio.
        poisson: f64,
    },
}

impl Bridge {
    /// Strain from the bridge ratio `V_r` (see the module table).
    pub fn strain(self, vr: f64, gauge_factor: f64) -> f64 {
        let gf = gauge_factor;
        match self {
            Bridge::Quarter => 4.0 * vr / (gf * (1.0 - 2.0 * vr)),
            Bridge::HalfPoisson { poisson: nu } => {
                4.0 * vr / (gf * ((1.0 + nu) - 2.0 * vr * (1.0 - nu)))
            }
            Bridge::HalfBending => 2.0 * vr / gf,
            Bridge::HalfAxial => 2.0 * vr / (gf * (1.0 - vr)),
            Bridge::FullBending => vr / gf,
            Bridge::FullBendingPoisson { poisson: nu } => 2.0 * vr / (gf * (1.0 + nu)),
            Bridge::FullPoisson { poisson: nu } => 2.0 * vr / (gf * ((1.0 + nu) - vr * (1.0 - nu))),
        }
    }

    /// The bridge ratio `V_r` a strain gives: the bridge's forward equation, from the arm
    /// resistances `R (1 + GF epsilon_i)` (for tests and for simulating a gauge).
    pub fn ratio(self, strain: f64, gauge_factor: f64) -> f64 {
        let a = gauge_factor * strain;
        // Arms 1, 2 form one divider, 4, 3 the other: V_r = R1/(R1+R2) - R4/(R3+R4).
        let (r1, r2, r3, r4) = match self {
            Bridge::Quarter => (1.0 + a, 1.0, 1.0, 1.0),
            Bridge::HalfPoisson { poisson: nu } => (1.0 + a, 1.0 - nu * a, 1.0, 1.0),
            Bridge::HalfBending => (1.0 + a, 1.0 - a, 1.0, 1.0),
            Bridge::HalfAxial => (1.0 + a, 1.0, 1.0 + a, 1.0),
            Bridge::FullBending => (1.0 + a, 1.0 - a, 1.0 + a, 1.0 - a),
            Bridge::FullBendingPoisson { poisson: nu } => {
                (1.0 + a, 1.0 - a, 1.0 + nu * a, 1.0 - nu * a)
            }
            Bridge::FullPoisson { poisson: nu } => (1.0 + a, 1.0 - nu * a, 1.0 + a, 1.0 - nu * a),
        };
        r1 / (r1 + r2) - r4 / (r3 + r4)
    }
}

/// A unit a channel may be recorded in, with its exact factor to SI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Unit {
    /// Standard gravity, 9.80665 m/s^2.
    G,
    /// 1,000 g (`kg_n` of high-g accelerometers).
    KiloG,
    /// Millimetre.
    Millimetre,
    /// Inch, 0.0254 m.
    Inch,
    /// Foot, 0.3048 m.
    Foot,
    /// Millisecond.
    Millisecond,
    /// Microsecond.
    Microsecond,
    /// Millimetre per second.
    MillimetrePerSecond,
    /// Inch per second.
    InchPerSecond,
    /// Foot per second.
    FootPerSecond,
    /// Kilometre per hour.
    KilometrePerHour,
    /// Kilonewton.
    Kilonewton,
    /// Pound-force, 4.4482216152605 N.
    PoundForce,
    /// Megapascal.
    Megapascal,
    /// Pound-force per square inch, 6894.757293168 Pa.
    Psi,
    /// Microstrain.
    Microstrain,
    /// Millivolt.
    Millivolt,
}

impl Unit {
    /// Every unit with the name it is written as.
    pub const ALL: [(Unit, &'static str); 17] = [
        (Unit::G, "g"),
        (Unit::KiloG, "kg_n"),
        (Unit::Millimetre, "mm"),
        (Unit::Inch, "in"),
        (Unit::Foot, "ft"),
        (Unit::Millisecond, "ms"),
        (Unit::Microsecond, "us"),
        (Unit::MillimetrePerSecond, "mm/s"),
        (Unit::InchPerSecond, "in/s"),
        (Unit::FootPerSecond, "ft/s"),
        (Unit::KilometrePerHour, "km/h"),
        (Unit::Kilonewton, "kN"),
        (Unit::PoundForce, "lbf"),
        (Unit::Megapascal, "MPa"),
        (Unit::Psi, "psi"),
        (Unit::Microstrain, "microstrain"),
        (Unit::Millivolt, "mV"),
    ];

    /// The factor that turns a value in this unit into SI.
    pub fn to_si(self) -> f64 {
        match self {
            Unit::G => STANDARD_GRAVITY,
            Unit::KiloG => 1000.0 * STANDARD_GRAVITY,
            Unit::Millimetre | Unit::Millisecond | Unit::MillimetrePerSecond => 1e-3,
            Unit::Inch | Unit::InchPerSecond => 0.0254,
            Unit::Foot | Unit::FootPerSecond => 0.3048,
            Unit::Microsecond | Unit::Microstrain => 1e-6,
            Unit::KilometrePerHour => 1.0 / 3.6,
            Unit::Kilonewton => 1e3,
            Unit::PoundForce => 4.448_221_615_260_5,
            Unit::Megapascal => 1e6,
            Unit::Psi => 4.448_221_615_260_5 / (0.0254 * 0.0254),
            Unit::Millivolt => 1e-3,
        }
    }

    /// The unit written `name` (as in [`Unit::ALL`]).
    pub fn named(name: &str) -> Option<Unit> {
        Unit::ALL.iter().find(|(_, n)| *n == name).map(|(u, _)| *u)
    }
}

/// A conversion of a raw test channel into SI.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Conversion {
    /// A strain-gauge bridge: volts in, strain out.
    Bridge {
        /// How the gauges are placed.
        bridge: Bridge,
        /// Gauge factor `GF`.
        gauge_factor: f64,
        /// Amplifier gain `G`.
        gain: f64,
        /// Excitation voltage `V_ex` (V).
        excitation: f64,
    },
    /// An accelerometer: volts in, m/s^2 out.
    Accelerometer {
        /// Sensitivity (mV/g).
        mv_per_g: f64,
        /// Amplifier gain `G`.
        gain: f64,
    },
    /// A channel in a non-SI unit: multiplied by the unit's factor.
    Unit {
        /// The channel's unit.
        from: Unit,
    },
}

impl Conversion {
    /// The converted value of raw sample `v`.
    pub fn apply(&self, v: f64) -> f64 {
        match *self {
            Conversion::Bridge {
                bridge,
                gauge_factor,
                gain,
                excitation,
            } => bridge.strain(v / (gain * excitation), gauge_factor),
            Conversion::Accelerometer { mv_per_g, gain } => {
                v / (gain * mv_per_g * 1e-3) * STANDARD_GRAVITY
            }
            Conversion::Unit { from } => v * from.to_si(),
        }
    }

    /// Parses the text form `kind key=value ...`:
    /// `quarter-bridge gf=2.06 gain=200 excitation=8`, `half-bridge-poisson gf= gain=
    /// excitation= nu=`, `half-bridge-bending ...`, `full-bridge-bending ...`,
    /// `full-bridge-bending-poisson ... nu=`, `full-bridge-poisson ... nu=`,
    /// `accelerometer mv-per-g=0.5 [gain=1]`, `unit from=g`. Gains default to 1.
    ///
    /// # Errors
    /// A message naming the unknown kind or key, the missing key, or the value that is not a
    /// finite number of the right sign (gauge factor, gains, excitation and sensitivity
    /// non-zero; Poisson's ratio in `[0, 0.5]`).
    pub fn parse(text: &str) -> std::result::Result<Conversion, String> {
        let mut words = text.split_whitespace();
        let kind = words.next().ok_or("empty conversion")?;
        let mut pairs: Vec<(&str, &str)> = Vec::new();
        for w in words {
            let (k, v) = w
                .split_once('=')
                .ok_or_else(|| format!("`{w}` is not `key=value`"))?;
            pairs.push((k, v));
        }
        let allowed: &[&str] = match kind {
            "quarter-bridge"
            | "half-bridge-bending"
            | "half-bridge-axial"
            | "full-bridge-bending" => &["gf", "gain", "excitation"],
            "half-bridge-poisson" | "full-bridge-poisson" | "full-bridge-bending-poisson" => {
                &["gf", "gain", "excitation", "nu"]
            }
            "accelerometer" => &["mv-per-g", "gain"],
            "unit" => &["from"],
            _ => {
                return Err(format!(
                    "unknown conversion `{kind}` (quarter-bridge, half-bridge-poisson, \
                     half-bridge-bending, half-bridge-axial, full-bridge-bending, full-bridge-bending-poisson, \
                     full-bridge-poisson, accelerometer, unit)"
                ));
            }
        };
        if let Some((k, _)) = pairs.iter().find(|(k, _)| !allowed.contains(k)) {
            return Err(format!(
                "`{k}` is not a key of `{kind}` ({})",
                allowed.join(", ")
            ));
        }
        let raw = |key: &str| pairs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
        let number = |key: &str, default: Option<f64>| -> std::result::Result<f64, String> {
            let v = match raw(key) {
                Some(s) => s
                    .parse::<f64>()
                    .map_err(|_| format!("{key}=`{s}` is not a number"))?,
                None => default.ok_or_else(|| format!("`{kind}` needs {key}="))?,
            };
            if !v.is_finite() || v == 0.0 {
                return Err(format!("{key}={v} must be finite and non-zero"));
            }
            Ok(v)
        };
        let nu = || -> std::result::Result<f64, String> {
            let s = raw("nu").ok_or_else(|| format!("`{kind}` needs nu="))?;
            let v: f64 = s.parse().map_err(|_| format!("nu=`{s}` is not a number"))?;
            if !(0.0..=0.5).contains(&v) {
                return Err(format!("nu={v} must lie in [0, 0.5]"));
            }
            Ok(v)
        };
        let bridge = match kind {
            "quarter-bridge" => Some(Bridge::Quarter),
            "half-bridge-poisson" => Some(Bridge::HalfPoisson { poisson: nu()? }),
            "half-bridge-bending" => Some(Bridge::HalfBending),
            "half-bridge-axial" => Some(Bridge::HalfAxial),
            "full-bridge-bending" => Some(Bridge::FullBending),
            "full-bridge-bending-poisson" => Some(Bridge::FullBendingPoisson { poisson: nu()? }),
            "full-bridge-poisson" => Some(Bridge::FullPoisson { poisson: nu()? }),
            _ => None,
        };
        if let Some(bridge) = bridge {
            let excitation = number("excitation", None)?;
            if excitation < 0.0 {
                return Err(format!("excitation={excitation} must be positive"));
            }
            return Ok(Conversion::Bridge {
                bridge,
                gauge_factor: number("gf", None)?,
                gain: number("gain", Some(1.0))?,
                excitation,
            });
        }
        if kind == "accelerometer" {
            return Ok(Conversion::Accelerometer {
                mv_per_g: number("mv-per-g", None)?,
                gain: number("gain", Some(1.0))?,
            });
        }
        let name = raw("from").ok_or("`unit` needs from=")?;
        let from = Unit::named(name).ok_or_else(|| {
            format!(
                "unknown unit `{name}` ({})",
                Unit::ALL
                    .iter()
                    .map(|(_, n)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })?;
        Ok(Conversion::Unit { from })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bridge_inverts_its_own_forward_equation() {
        // The strain formulas of the module table against the divider ratios of the arms:
        // exact for every configuration (the linear ones because their arms change in
        // opposite pairs), at small and at large strain.
        let bridges = [
            Bridge::Quarter,
            Bridge::HalfPoisson { poisson: 0.3 },
            Bridge::HalfBending,
            Bridge::HalfAxial,
            Bridge::FullBending,
            Bridge::FullBendingPoisson { poisson: 0.33 },
            Bridge::FullPoisson { poisson: 0.29 },
        ];
        for b in bridges {
            for eps in [-0.02, -1e-3, 1e-6, 2.5e-3, 0.05] {
                let vr = b.ratio(eps, 2.1);
                let back = b.strain(vr, 2.1);
                // The forward ratio loses digits to cancellation at small strain.
                assert!((back - eps).abs() < 1e-9 * eps.abs(), "{b:?} {eps}: {back}");
            }
        }
        // The textbook small-strain sensitivities: quarter GF/4, half bending and half axial
        // GF/2, full bending GF, full Poisson GF (1 + nu) / 2 (per unit strain).
        let s = |b: Bridge| b.ratio(1e-7, 2.0) / 1e-7;
        assert!((s(Bridge::Quarter) - 0.5).abs() < 1e-6);
        assert!((s(Bridge::HalfBending) - 1.0).abs() < 1e-9);
        assert!((s(Bridge::HalfAxial) - 1.0).abs() < 1e-6);
        assert!((s(Bridge::FullBending) - 2.0).abs() < 1e-9);
        assert!((s(Bridge::FullPoisson { poisson: 0.3 }) - 1.3).abs() < 1e-6);
    }

    #[test]
    fn the_kolsky_incident_gauge_by_hand() {
        // 3.0 V out of a quarter bridge at gain 200, 8 V excitation, GF 2.061:
        // V_r = 3 / 1600 = 1.875e-3; epsilon = 4 V_r / (GF (1 - 2 V_r)) = 3.6526e-3.
        let c = Conversion::parse("quarter-bridge gf=2.061 gain=200 excitation=8").unwrap();
        let vr: f64 = 3.0 / 1600.0;
        let expect = 4.0 * vr / (2.061 * (1.0 - 2.0 * vr));
        assert!((c.apply(3.0) - expect).abs() < 1e-15);
        assert!((c.apply(3.0) - 3.6526e-3).abs() < 1e-6, "{}", c.apply(3.0));
    }

    #[test]
    fn accelerometers_and_units_to_si() {
        // 10 mV/g behind a gain of 2: 1 V is 50 g.
        let c = Conversion::parse("accelerometer mv-per-g=10 gain=2").unwrap();
        assert!((c.apply(1.0) - 50.0 * 9.80665).abs() < 1e-12);
        let c = Conversion::parse("accelerometer mv-per-g=0.05").unwrap();
        assert!((c.apply(0.5) - 1e4 * 9.80665).abs() < 1e-9);
        let u = |n: &str, v: f64| {
            Conversion::parse(&format!("unit from={n}"))
                .unwrap()
                .apply(v)
        };
        assert!((u("in", 1.0) - 0.0254).abs() < 1e-15);
        assert!((u("lbf", 1.0) - 4.4482216152605).abs() < 1e-13);
        assert!((u("psi", 1.0) - 6894.757293168361).abs() < 1e-8);
        assert!((u("kg_n", 2.0) - 19613.3).abs() < 1e-9);
        assert!((u("km/h", 36.0) - 10.0).abs() < 1e-12);
        for (unit, name) in Unit::ALL {
            assert_eq!(Unit::named(name), Some(unit));
        }
    }

    #[test]
    fn malformed_conversions_say_what_is_wrong() {
        let e = |t: &str| Conversion::parse(t).unwrap_err();
        assert!(e("").contains("empty"));
        assert!(e("third-bridge gf=2").contains("unknown conversion"));
        assert!(e("quarter-bridge gf=2 gain=1").contains("needs excitation"));
        assert!(e("quarter-bridge gf=x excitation=5").contains("not a number"));
        assert!(e("quarter-bridge gf=0 excitation=5").contains("non-zero"));
        assert!(e("quarter-bridge gf=2 excitation=-5").contains("positive"));
        assert!(e("quarter-bridge gf=2 excitation=5 nu=0.3").contains("not a key"));
        assert!(e("half-bridge-poisson gf=2 excitation=5").contains("needs nu"));
        assert!(e("full-bridge-poisson gf=2 excitation=5 nu=0.7").contains("[0, 0.5]"));
        assert!(e("unit from=furlong").contains("unknown unit"));
        assert!(e("accelerometer 5").contains("key=value"));
    }
}
