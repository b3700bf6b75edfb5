//! Sanity first: data that do not fit the declared units or attitudes are refused before
//! anything is written. Each check names the segment, its lines in the source, and the
//! map key to fix.

pub mod feedback;

use crate::error::{ErrorKind, ImportError, Say};
use crate::map::{DeclSegment, ImportMap, RateAxis, Segments, Up};
use crate::segment::{Found, detect::up_of, norm};
use ratecal_physics::units::{Dim, unit};
use ratecal_recording::SegmentKind;
use std::ops::Range;

/// Static specific force accepted: 0.25 g to 4 g of the site's gravity (raw offsets of a
/// consumer IMU, 0.5 g, pass; a unit off by 9.81 or 1000 does not).
pub const GRAVITY_RANGE: (f64, f64) = (0.25, 4.0);
/// A gyro at rest reading more than this is not a plausible bias, deg/s (a consumer
/// MEMS gyro's zero-rate offset is within +-20 deg/s).
pub const GYRO_REST_MAX_DPS: f64 = 25.0;
/// A rate segment's measured mean rate about its axis, as a fraction of the declared one.
pub const RATE_RATIO: (f64, f64) = (0.5, 2.0);
/// A declared up axis further than this from the measured gravity is contradicted, deg.
pub const UP_TOLERANCE_DEG: f64 = 30.0;

/// Refuses the first segment whose data contradict the map. `source` names the first
/// source (for the lines quoted).
pub fn check(map: &ImportMap, found: &[Found], source: &str) -> Result<(), Box<ImportError>> {
    let g = map.site.gravity_mps2;
    let decl = |f: &Found| match (&map.segments, f.decl) {
        (Segments::List(v), Some(k)) => v.get(k),
        _ => None,
    };
    for f in found {
        let s = &f.stretch;
        let lines = format!("{source} lines {}-{}", s.lines.0, s.lines.1);
        match f.kind {
            SegmentKind::Static => {
                let m = s.mag_f.median();
                let r = m / g;
                if !(GRAVITY_RANGE.0..=GRAVITY_RANGE.1).contains(&r) {
                    let looks = likely_unit(m / map.accel.factor, g, Dim::Accel);
                    let what = format!(
                        "static segment `{}` ({lines}): the median specific force is {m:.4} \
                         m/s^2, {r:.3} times gravity ({g} m/s^2)",
                        f.id
                    );
                    let help = match looks {
                        Some(u) => format!(
                            "the accelerometer columns look like {u}, not {}: set units.accel",
                            map.accel.unit
                        ),
                        None => "no unit makes this gravity: check units.accel, zero.accel \
                                 and the columns"
                            .into(),
                    };
                    return Err(at_map(
                        map,
                        map.accel.at.clone(),
                        ErrorKind::Units,
                        &what,
                        &help,
                    ));
                }
                let wm = s.mag_w.median();
                if wm > GYRO_REST_MAX_DPS {
                    let what = format!(
                        "static segment `{}` ({lines}): the gyros at rest read {wm:.3} deg/s, \
                         not a plausible bias",
                        f.id
                    );
                    let help = format!(
                        "a gyro at rest reads its bias (under {GYRO_REST_MAX_DPS} deg/s): check \
                         units.gyro (`{}`: deg/s or rad/s?) and zero.gyro (unsigned counts \
                         need their zero)",
                        map.gyro.unit
                    );
                    return Err(at_map(
                        map,
                        map.gyro.at.clone(),
                        ErrorKind::Units,
                        &what,
                        &help,
                    ));
                }
                if let (Some(Up::Axis(k, sign)), Some(d)) = (f.up, decl(f)) {
                    check_up(map, d, f, k, sign, &lines)?;
                }
            }
            SegmentKind::Rate => {
                let (Some((RateAxis::Body(k, sign), rate)), Some(d)) = (f.rate, decl(f)) else {
                    continue;
                };
                let measured = s.mean_w()[k] * sign;
                let ratio = measured / rate;
                if !(RATE_RATIO.0..=RATE_RATIO.1).contains(&ratio) {
                    let what = format!(
                        "rate segment `{}` ({lines}): the gyros read {measured:.3} deg/s about \
                         its axis, the map declares {rate} deg/s",
                        f.id
                    );
                    let looks =
                        likely_unit(measured.abs() / map.gyro.factor, rate.abs(), Dim::Rate);
                    let help = match looks {
                        Some(u) if u != map.gyro.unit => format!(
                            "the gyro columns look like {u}, not {}: set units.gyro",
                            map.gyro.unit
                        ),
                        _ => "check units.gyro, the axis and sign (imu.axes), and rate_dps (the \
                              mean rate over the segment)"
                            .into(),
                    };
                    return Err(at_map(map, d.at.clone(), ErrorKind::Units, &what, &help));
                }
            }
            SegmentKind::Turn => check_turn(map, f, decl(f), &lines)?,
            SegmentKind::Oscillation => {}
        }
    }
    Ok(())
}

/// A turn whose map states its axis and angle: the gyros integrated over it must turn
/// about that much (half to twice), as a rate segment must read its rate. A gyro unit off
/// by 3600 (`deg/h` for deg/s) or 57 turns a 360 deg turn into a tenth of a degree.
fn check_turn(
    map: &ImportMap,
    f: &Found,
    d: Option<&DeclSegment>,
    lines: &str,
) -> Result<(), Box<ImportError>> {
    let (Some(t), Some(d)) = (&f.turn, d) else {
        return Ok(());
    };
    let (Some((k, sign)), Some(angle)) = (t.axis, t.angle_deg) else {
        return Ok(());
    };
    let s = &f.stretch;
    let turned = s.mean_w()[k] * sign * (s.t.1 - s.t.0);
    let ratio = turned / angle;
    if angle.abs() < 30.0 || (RATE_RATIO.0..=RATE_RATIO.1).contains(&ratio) {
        return Ok(());
    }
    let what = format!(
        "turn segment `{}` ({lines}): the gyros turn {turned:.3} deg about its axis, the map \
         declares {angle} deg",
        f.id
    );
    let raw = turned.abs() / (s.t.1 - s.t.0).max(f64::MIN_POSITIVE) / map.gyro.factor;
    let expect = angle.abs() / (s.t.1 - s.t.0).max(f64::MIN_POSITIVE);
    let help = match likely_unit(raw, expect, Dim::Rate) {
        Some(u) if u != map.gyro.unit => format!(
            "the gyro columns look like {u}, not {}: set units.gyro",
            map.gyro.unit
        ),
        _ => "check units.gyro, the turn's axis and sign (imu.axes), its angle_deg and its \
              samples (the whole turn, rest to rest)"
            .into(),
    };
    Err(at_map(map, d.at.clone(), ErrorKind::Units, &what, &help))
}

fn check_up(
    map: &ImportMap,
    d: &DeclSegment,
    f: &Found,
    k: usize,
    sign: f64,
    lines: &str,
) -> Result<(), Box<ImportError>> {
    let mean = f.stretch.mean_f();
    let cos = mean[k] * sign / norm(&mean);
    if cos >= UP_TOLERANCE_DEG.to_radians().cos() {
        return Ok(());
    }
    let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
    let what = format!(
        "static segment `{}` ({lines}): `up: {}` is {angle:.0} deg from gravity",
        f.id,
        Up::Axis(k, sign).name()
    );
    let help = match up_of(&mean) {
        Up::Axis(i, s) => format!(
            "gravity says {} is up; fix `up`, or imu.axes if the sensor axes differ from the body's",
            Up::Axis(i, s).name()
        ),
        Up::Oblique => "gravity says no body axis is up: write `up: oblique`".into(),
    };
    Err(at_map(map, d.up_at.clone(), ErrorKind::Up, &what, &help))
}

/// The unit (of `dim`, the language's) in which `raw` (the column's own magnitude) would be
/// `expect` (in internal units) within 30 %, if one is.
pub(crate) fn likely_unit(raw: f64, expect: f64, dim: Dim) -> Option<&'static str> {
    let names: &[&str] = match dim {
        Dim::Accel => &["m/s^2", "g", "mg", "ug"],
        Dim::Angle => &["deg", "rad", "mrad"],
        _ => &["deg/s", "rad/s", "deg/h"],
    };
    names.iter().copied().find(|n| {
        unit(n).is_some_and(|(_, f)| {
            let r = raw * f / expect;
            (0.7..=1.3).contains(&r)
        })
    })
}

pub(crate) fn at_map(
    map: &ImportMap,
    at: Range<usize>,
    kind: ErrorKind,
    what: &str,
    help: &str,
) -> Box<ImportError> {
    ImportError::in_text(
        kind,
        &map.file,
        &map.text,
        at,
        Say {
            what,
            label: "declared here",
            help,
        },
    )
}
