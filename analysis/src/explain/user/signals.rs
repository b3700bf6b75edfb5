//! The names a user effect's expression may read: the kinematic signals of one instant
//! (the registry's [`Signals`], which the simulator and the analysis build through the same
//! kinematics), a few constants and the functions. docs/user-effects.md lists the same
//! table; a test keeps the two in step.

use ratecal_physics::effects::Signals;

/// One named scalar signal.
#[derive(Clone, Copy)]
pub struct SignalDef {
    /// Name as written in an expression (`w_b.x`).
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Reads it from the signals of one instant.
    pub get: fn(&Signals) -> f64,
}

macro_rules! vector {
    ($base:literal, $unit:literal, |$s:ident| $v:expr) => {
        [
            SignalDef {
                name: concat!($base, ".x"),
                unit: $unit,
                get: |$s| $v[0],
            },
            SignalDef {
                name: concat!($base, ".y"),
                unit: $unit,
                get: |$s| $v[1],
            },
            SignalDef {
                name: concat!($base, ".z"),
                unit: $unit,
                get: |$s| $v[2],
            },
        ]
    };
}

/// Every signal, vectors in body axes.
pub fn signals() -> Vec<SignalDef> {
    let mut v = Vec::new();
    v.extend(vector!("f_b", "m/s^2", |s| s.f_b));
    v.extend(vector!("w_b", "rad/s", |s| s.w_b));
    v.extend(vector!("dw_b", "rad/s^2", |s| s.dw_b));
    v.extend(vector!("w_ib", "rad/s", |s| s.w_b + s.earth_b));
    v.extend(vector!("earth_b", "rad/s", |s| s.earth_b));
    v.extend(vector!("df_b", "m/s^3", |s| s.df_b));
    v.extend(vector!("dw_ib", "rad/s^2", |s| s.dw_ib));
    // Columns of C_BL: the lab's East, North and Up axes seen in body axes (the attitude).
    v.extend(vector!("east_b", "1", |s| s.c_bl.column(0)));
    v.extend(vector!("north_b", "1", |s| s.c_bl.column(1)));
    v.extend(vector!("up_b", "1", |s| s.c_bl.column(2)));
    v.push(SignalDef {
        name: "dtemp_c",
        unit: "degC",
        get: |s| s.dtemp_c,
    });
    v.push(SignalDef {
        name: "t_s",
        unit: "s",
        get: |s| s.t_s,
    });
    v.push(SignalDef {
        name: "g",
        unit: "m/s^2",
        get: |s| s.g,
    });
    v
}

/// Named constants: `pi`, and `deg` (one degree in radians: `w_b.x / deg` is deg/s).
pub const CONSTANTS: [(&str, f64); 2] =
    [("pi", std::f64::consts::PI), ("deg", ratecal_physics::DEG)];

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fun {
    /// `sin`, radians.
    Sin,
    /// `cos`, radians.
    Cos,
    /// `tan`, radians.
    Tan,
    /// `sqrt`.
    Sqrt,
    /// `abs`.
    Abs,
    /// `exp`.
    Exp,
    /// `ln`, natural logarithm.
    Ln,
    /// `sign`: -1, 0 or 1.
    Sign,
}

/// The functions by name.
pub const FUNCTIONS: [(&str, Fun); 8] = [
    ("sin", Fun::Sin),
    ("cos", Fun::Cos),
    ("tan", Fun::Tan),
    ("sqrt", Fun::Sqrt),
    ("abs", Fun::Abs),
    ("exp", Fun::Exp),
    ("ln", Fun::Ln),
    ("sign", Fun::Sign),
];

impl Fun {
    /// Applies it.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Fun::Sin => x.sin(),
            Fun::Cos => x.cos(),
            Fun::Tan => x.tan(),
            Fun::Sqrt => x.sqrt(),
            Fun::Abs => x.abs(),
            Fun::Exp => x.exp(),
            Fun::Ln => x.ln(),
            Fun::Sign => {
                if x == 0.0 {
                    0.0
                } else {
                    x.signum()
                }
            }
        }
    }
}

/// The output channels a contribution may name, in layout order, with their units.
pub const CHANNELS: [(&str, &str); 6] = [
    ("ax", "m/s^2"),
    ("ay", "m/s^2"),
    ("az", "m/s^2"),
    ("gx", "deg/s"),
    ("gy", "deg/s"),
    ("gz", "deg/s"),
];
