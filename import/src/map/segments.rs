//! The declared segments of a map: ranges in order, without overlap, each with what its
//! kind needs (`up` for a static one without table feedback, `axis` and `rate_dps` for a
//! rate one: a table axis when there is feedback).

use super::raw::RawSegment;
use super::resolve::{HELP, Res, Resolver};
use super::*;
use serde_saphyr::Spanned;

impl Resolver<'_> {
    pub(super) fn segments(
        &self,
        list: &[Spanned<RawSegment>],
        feedback: bool,
    ) -> Res<Vec<DeclSegment>> {
        let mut out: Vec<DeclSegment> = Vec::with_capacity(list.len());
        for s in list {
            let d = self.segment(s, feedback)?;
            if let Some(o) = out.iter().find(|o| o.id == d.id) {
                let _ = o;
                return Err(self.err(
                    d.at.clone(),
                    &format!("segment id `{}` is used twice", d.id),
                    "segment ids name one segment each",
                ));
            }
            if let Some(prev) = out.last() {
                let order = match (prev.range, d.range) {
                    (SegRange::Samples(_, a), SegRange::Samples(b, _)) => Some(b >= a),
                    (SegRange::Time(_, a), SegRange::Time(b, _)) => Some(b >= a),
                    _ => None,
                };
                if order == Some(false) {
                    return Err(self.err(
                        d.range_at.clone(),
                        &format!(
                            "segment `{}` starts before `{}` ends: overlapping or out of order",
                            d.id, prev.id
                        ),
                        "list segments in time order, each ending at or before the next starts",
                    ));
                }
            }
            out.push(d);
        }
        Ok(out)
    }

    fn segment(&self, s: &Spanned<RawSegment>, feedback: bool) -> Res<DeclSegment> {
        let v = &s.value;
        let at = self.at(&s.referenced);
        let kind = match v.kind.value.as_str() {
            "static" => SegmentKind::Static,
            "rate" => SegmentKind::Rate,
            "turn" => SegmentKind::Turn,
            k => {
                return Err(self.err(
                    self.at(&v.kind.referenced),
                    &format!("segment kind `{k}` cannot be imported"),
                    "kind is `static`, `rate` or `turn` (an oscillation needs the table's \
                     feedback)",
                ));
            }
        };
        let (range, range_at) = match (&v.samples, &v.time) {
            (Some(r), None) => {
                let at = self.at(&r.referenced);
                if r.value[0] >= r.value[1] {
                    return Err(self.err(at, "samples [from, to) needs from < to", HELP));
                }
                (SegRange::Samples(r.value[0], r.value[1]), at)
            }
            (None, Some(r)) => {
                let at = self.at(&r.referenced);
                if r.value[0].partial_cmp(&r.value[1]) != Some(std::cmp::Ordering::Less)
                    || !r.value[1].is_finite()
                {
                    return Err(self.err(at, "time [t0, t1) needs t0 < t1", HELP));
                }
                (SegRange::Time(r.value[0], r.value[1]), at)
            }
            _ => {
                return Err(self.err(
                    at,
                    &format!(
                        "segment `{}` needs `samples` or `time` (one of them)",
                        v.id.value
                    ),
                    "samples: [from, to) (0-based, to excluded) or time: [t0, t1) in seconds",
                ));
            }
        };
        let up_at = v.up.as_ref().map_or(at.clone(), |u| self.at(&u.referenced));
        let up = match &v.up {
            None => None,
            Some(u) if u.value == "oblique" => Some(Up::Oblique),
            Some(u) => Some(
                signed_axis(&u.value)
                    .map(|(i, s)| Up::Axis(i, s))
                    .ok_or_else(|| {
                        self.err(
                            up_at.clone(),
                            &format!("`{}` is not an axis", u.value),
                            "up is a body axis with its sign (+x, -z...) or `oblique`",
                        )
                    })?,
            ),
        };
        let attitude = self.seg_attitude(v, feedback)?;
        let unknown = attitude == Some(Attitude::Unknown);
        let rate = match kind {
            SegmentKind::Static => {
                if up.is_none() && !feedback && !unknown {
                    return Err(self.err(
                        at,
                        &format!("static segment `{}` needs `up`", v.id.value),
                        "without table feedback the attitude comes from `up`: the body axis \
                         that points up (+x, -z...), or `attitude: unknown` for a hand-held pose",
                    ));
                }
                if matches!(attitude, Some(Attitude::Nominal(_)))
                    && !matches!(up, Some(Up::Axis(..)))
                {
                    return Err(self.err(
                        at,
                        &format!(
                            "nominal static segment `{}` needs `up` (a body axis)",
                            v.id.value
                        ),
                        "a nominal attitude is a face: `up: +x`, `up: -z`...",
                    ));
                }
                None
            }
            SegmentKind::Turn => None,
            _ => {
                let (Some(axis), Some(r)) = (&v.axis, &v.rate_dps) else {
                    return Err(self.err(
                        at,
                        &format!("rate segment `{}` needs `axis` and `rate_dps`", v.id.value),
                        "axis: a body axis (x, -y...) or the table's outer/inner; rate_dps: the \
                         mean rate over the segment, deg/s",
                    ));
                };
                let ax = match axis.value.as_str() {
                    "outer" => RateAxis::Outer,
                    "inner" => RateAxis::Inner,
                    a => signed_axis(a)
                        .map(|(i, s)| RateAxis::Body(i, s))
                        .ok_or_else(|| {
                            self.err(
                                self.at(&axis.referenced),
                                &format!("`{a}` is not an axis"),
                                "axis is a body axis (x, -y...) or outer/inner",
                            )
                        })?,
                };
                if !r.value.is_finite() {
                    return Err(self.err(self.at(&r.referenced), "rate_dps must be finite", HELP));
                }
                if feedback && matches!(ax, RateAxis::Body(..)) {
                    return Err(self.err(
                        self.at(&axis.referenced),
                        &format!("rate segment `{}` turns about a body axis", v.id.value),
                        "with table feedback a rate segment names the table axis it turns: \
                         `axis: outer` or `axis: inner`",
                    ));
                }
                Some((ax, r.value))
            }
        };
        let turn = match kind {
            SegmentKind::Turn => Some(self.turn(v)?),
            _ => None,
        };
        Ok(DeclSegment {
            id: v.id.value.clone(),
            kind,
            range,
            up: if unknown && up.is_none() {
                Some(Up::Oblique)
            } else {
                up
            },
            rate,
            turn,
            attitude,
            at,
            range_at,
            up_at,
        })
    }
}
