//! A segment's `attitude` (with `tolerance_deg`) and a turn's `axis` and `angle_deg`, as
//! the map declares them (spec/recording-format.md).

use super::raw::{RawDetect, RawSegment};
use super::resolve::{Res, Resolver};
use super::{Attitude, Turn, signed_axis};
use serde_saphyr::Spanned;

const ATTITUDE_HELP: &str = "attitude is `feedback` (the table's feedback holds it), `nominal` \
                             (a fixture's face, with `tolerance_deg`) or `unknown` (a hand-held \
                             pose)";

impl Resolver<'_> {
    /// The declared attitude of a segment (`None` when the map gives none).
    pub(super) fn seg_attitude(&self, v: &RawSegment, feedback: bool) -> Res<Option<Attitude>> {
        self.attitude(v.attitude.as_ref(), v.tolerance_deg.as_ref(), feedback)
    }

    /// The detected poses' attitude.
    pub(super) fn detect_attitude(&self, d: &RawDetect, feedback: bool) -> Res<Option<Attitude>> {
        self.attitude(d.attitude.as_ref(), d.tolerance_deg.as_ref(), feedback)
    }

    fn attitude(
        &self,
        word: Option<&Spanned<String>>,
        tol: Option<&Spanned<f64>>,
        feedback: bool,
    ) -> Res<Option<Attitude>> {
        let Some(w) = word else {
            if let Some(t) = tol {
                return Err(self.err(
                    self.at(&t.referenced),
                    "`tolerance_deg` without `attitude: nominal`",
                    "tolerance_deg says how well a nominal attitude is known: add `attitude: \
                     nominal`, or remove it",
                ));
            }
            return Ok(None);
        };
        let at = self.at(&w.referenced);
        match w.value.as_str() {
            "feedback" if feedback => Ok(Some(Attitude::Feedback)),
            "feedback" => Err(self.err(
                at,
                "`attitude: feedback` without the table's feedback (`table: none`)",
                "without a feedback file the attitude is `nominal` (with tolerance_deg) or \
                 `unknown`",
            )),
            "unknown" => Ok(Some(Attitude::Unknown)),
            "nominal" => {
                let Some(t) = tol else {
                    return Err(self.err(
                        at,
                        "`attitude: nominal` needs `tolerance_deg`",
                        "say how well the face is known, in degrees: e.g. `tolerance_deg: 0.5` \
                         for a fixture placed on a bench",
                    ));
                };
                if !(t.value.is_finite() && t.value > 0.0) {
                    return Err(self.err(
                        self.at(&t.referenced),
                        "tolerance_deg must be a positive number of degrees",
                        "e.g. `tolerance_deg: 0.5`",
                    ));
                }
                Ok(Some(Attitude::Nominal(t.value)))
            }
            other => Err(self.err(at, &format!("`{other}` is not an attitude"), ATTITUDE_HELP)),
        }
    }

    /// A turn's axis (a signed body axis) and nominal angle.
    pub(super) fn turn(&self, v: &RawSegment) -> Res<Turn> {
        let axis = match &v.axis {
            None => None,
            Some(a) => Some(signed_axis(&a.value).ok_or_else(|| {
                self.err(
                    self.at(&a.referenced),
                    &format!("`{}` is not a body axis", a.value),
                    "a turn's axis is a body axis with its sign (x, -y, z...)",
                )
            })?),
        };
        let angle_deg = match &v.angle_deg {
            Some(a) if !a.value.is_finite() || a.value == 0.0 => {
                return Err(self.err(
                    self.at(&a.referenced),
                    "angle_deg must be a finite, non-zero angle",
                    "the nominal angle of the turn about its axis, deg (e.g. -360)",
                ));
            }
            Some(a) if axis.is_none() => {
                return Err(self.err(
                    self.at(&a.referenced),
                    "angle_deg without `axis`",
                    "a nominal angle is about a body axis: add `axis` (x, -y...)",
                ));
            }
            a => a.as_ref().map(|a| a.value),
        };
        Ok(Turn { axis, angle_deg })
    }
}
