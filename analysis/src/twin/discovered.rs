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

/// Every term of the discovered findings that a probe column of the layout holds (a decay
/// whose time constant was refined between the grid's has none: it is left out).
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
                .find(|(_, p)| p.sensor == sensor && p.expression(ax) == t.expression);
            if let Some(&(e, _)) = hit {
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
