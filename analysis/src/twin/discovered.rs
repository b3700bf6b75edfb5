//! Physics explain discovered (a form of the probe library, written as a draft `.effect`
//! file) as part of the twin: each term of a discovered finding is a probe column of
//! explain's pass, which the twin's fit takes beside its own terms, and whose value is
//! the draft effect's parameter `k_<channel>` (the draft's regressor is the probe's
//! expression, its unit the probe's).

use crate::explain::Explanation;
use crate::explain::data::Data;
use crate::fit::joint::CHANNELS;
use ratecal_physics::effects::Sensor;

/// One term of a discovered finding: the finding's effect id (the draft's), the channel,
/// the layout effect and column holding its form, and the unit of its coefficient.
pub(super) struct DiscoveredTerm {
    /// The draft effect's id (the finding's `effect`).
    pub effect: String,
    /// Channel name, `ax` ... `gz`.
    pub channel: String,
    /// Layout index of the probe.
    pub probe: usize,
    /// Layout column of the term.
    pub column: usize,
    /// The coefficient's unit.
    pub unit: String,
}

/// The time constant of a decay's expression (`... exp(-(t_s - t0) / tau)`).
fn decay_tau(expr: &str) -> Option<f64> {
    let rest = &expr[expr.find("exp(-(t_s - ")?..];
    let after = &rest[rest.find(") / ")? + 4..];
    after[..after.find(')')?].trim().parse().ok()
}

/// The library decay on `sensor` nearest in `ln tau` to the decay written in `expr`: a
/// time constant refined between the grid's (docs/explain.md) is held in the twin by the
/// grid's column nearest to it.
fn nearest_decay(data: &Data, sensor: Sensor, expr: &str) -> Option<usize> {
    let tau = decay_tau(expr)?;
    data.probes
        .iter()
        .filter(|(_, p)| p.sensor == sensor)
        .filter_map(|q| Some((q.0, decay_tau(&q.1.expression(0))?)))
        .min_by(|a, b| (a.1 / tau).ln().abs().total_cmp(&(b.1 / tau).ln().abs()))
        .map(|(e, _)| e)
}

/// Every term of the discovered findings that a probe column of the layout holds (a decay
/// whose time constant was refined between the grid's takes the nearest grid decay's).
pub(super) fn terms(data: &Data, x: &Explanation) -> Vec<DiscoveredTerm> {
    let lay = &data.layout;
    let mut out = Vec::new();
    for f in x.findings.iter().filter(|f| f.discovered) {
        for t in &f.terms {
            let Some(c) = CHANNELS.iter().position(|ch| *ch == t.channel) else {
                continue;
            };
            let (sensor, ax) = if c < 3 {
                (Sensor::Accel, c)
            } else {
                (Sensor::Gyro, c - 3)
            };
            let hit = data
                .probes
                .iter()
                .find(|(_, p)| p.sensor == sensor && p.expression(ax) == t.expression)
                .map(|q| q.0)
                .or_else(|| nearest_decay(data, sensor, &t.expression));
            if let Some(e) = hit {
                out.push(DiscoveredTerm {
                    effect: f.effect.clone(),
                    channel: t.channel.clone(),
                    probe: e,
                    column: lay.columns_of(e).start + ax,
                    unit: t.unit.clone(),
                });
            }
        }
    }
    out
}
