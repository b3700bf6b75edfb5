//! The synthesized table's attitudes on the seed station (outer axis [0,-1,0], inner
//! [1,0,0], C_PB = I): which outer/inner angles put a body axis up, and which table axis
//! turns about a body axis. Found with the physics crate's kinematics, not tabulated.

use crate::map::RateAxis;
use ratecal_physics::{Geometry, Site, TableState};

/// Candidate rest attitudes (outer, inner), deg: the six faces of the seed station.
const FACES: [(f64, f64); 6] = [
    (0.0, 0.0),
    (0.0, 90.0),
    (90.0, 0.0),
    (0.0, 180.0),
    (0.0, -90.0),
    (-90.0, 0.0),
];

fn site() -> Site {
    Site {
        latitude_deg: 0.0,
        gravity_mps2: 9.8,
    }
}

/// The attitude (outer, inner), deg, at which body axis `axis` (0..3) with `sign` points
/// up (reads +g).
pub fn face_up(axis: usize, sign: f64) -> (f64, f64) {
    let geo = Geometry::seed();
    let zero = ratecal_physics::Vec3::zeros();
    FACES
        .into_iter()
        .find(|&(o, i)| {
            let f = TableState::at_rest_deg(o, i).f_b(&geo, &site(), &zero);
            f[axis] * sign > 9.0
        })
        .unwrap_or((0.0, 0.0))
}

/// A rotation about a body axis on the table: the attitude it starts from (the given one
/// when a table axis there is along the body axis, else the first face where one is), the
/// table axis (`true` for outer) and the table rate that gives `rate_dps` about the body axis.
pub fn turn(axis: RateAxis, rate_dps: f64, from: (f64, f64)) -> ((f64, f64), bool, f64) {
    let (k, sign) = match axis {
        RateAxis::Outer => return (from, true, rate_dps),
        RateAxis::Inner => return (from, false, rate_dps),
        RateAxis::Body(k, s) => (k, s),
    };
    let geo = Geometry::seed();
    let along = |(o, i): (f64, f64)| {
        let snap = TableState::at_rest_deg(o, i).snapshot(&geo, &site());
        [(true, snap.outer_b), (false, snap.inner_b)]
            .into_iter()
            .find_map(|(outer, a)| (a[k].abs() > 0.99).then_some((outer, a[k].signum())))
    };
    std::iter::once(from)
        .chain(FACES)
        .find_map(|att| along(att).map(|(outer, s)| (att, outer, rate_dps * sign * s)))
        .unwrap_or((from, false, rate_dps))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_match_the_seed_station_convention() {
        // The hand-converted example (shared/examples/real-ferraris-session) uses these.
        assert_eq!(face_up(0, 1.0), (90.0, 0.0));
        assert_eq!(face_up(0, -1.0), (-90.0, 0.0));
        assert_eq!(face_up(1, 1.0), (0.0, 90.0));
        assert_eq!(face_up(1, -1.0), (0.0, -90.0));
        assert_eq!(face_up(2, 1.0), (0.0, 0.0));
        assert_eq!(face_up(2, -1.0), (0.0, 180.0));
    }

    #[test]
    fn turns_about_body_axes() {
        // Body x is the inner axis at every attitude.
        assert_eq!(
            turn(RateAxis::Body(0, 1.0), 10.0, (0.0, 0.0)),
            ((0.0, 0.0), false, 10.0)
        );
        // Body y is minus the outer axis at inner 0.
        assert_eq!(
            turn(RateAxis::Body(1, 1.0), 10.0, (0.0, 0.0)),
            ((0.0, 0.0), true, -10.0)
        );
        // Body z: the outer axis once the inner axis stands at 90 deg.
        let (att, outer, r) = turn(RateAxis::Body(2, -1.0), 10.0, (0.0, 0.0));
        assert!(outer && att == (0.0, 90.0), "{att:?} {outer}");
        assert_eq!(r.abs(), 10.0);
    }
}
