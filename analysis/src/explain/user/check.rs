//! Checks one effect file: names (channels, parameters, signals, constants, functions),
//! required entries, and that every contribution is linear in the parameters (a sum of
//! terms each proportional to exactly one parameter, which the joint least-squares needs).
//! Reports every error at once; each regressor is then the contribution's derivative.

use super::expr::Ex;
use super::linear::{Class, Cx, lin, suggestion};
use super::signals::{CHANNELS, CONSTANTS, FUNCTIONS, SignalDef};
use ratecal_grammar::ast::{Span, Spanned};
use ratecal_grammar::effect::{EffectDef, EffectItem};
use ratecal_grammar::{Diagnostic, effect};
use std::collections::BTreeSet;

/// One regressor: parameter, channel (`ax` = 0 ... `gz` = 5), expression over signals.
pub(crate) struct Reg {
    pub param: usize,
    pub channel: usize,
    pub ex: Ex,
}

/// An effect that passed every check.
pub(crate) struct Checked {
    pub id: Spanned<String>,
    pub explanation: String,
    pub follows: String,
    /// Name, unit, needs.
    pub params: Vec<(String, String, String)>,
    pub regs: Vec<Reg>,
}

/// Checks a parsed file. `taken` are ids already in use: the registry's (`None`) and those
/// of files read before (`Some(file)`).
pub(crate) fn check(
    file: &effect::EffectFile,
    signals: &[SignalDef],
    taken: &[(&str, Option<&str>)],
) -> Result<Vec<Checked>, Vec<Diagnostic>> {
    let mut diags = Vec::new();
    let mut out = Vec::new();
    let mut seen: Vec<&Spanned<String>> = Vec::new();
    for e in &file.effects {
        if let Some((_, origin)) = taken.iter().find(|t| t.0 == e.name.node) {
            let (message, label) = match origin {
                None => (
                    format!("`{}` is a built-in effect", e.name.node),
                    "already in the registry".to_string(),
                ),
                Some(f) => (
                    format!("effect `{}` is also defined in {f}", e.name.node),
                    format!("defined in {f} too"),
                ),
            };
            diags.push(
                Diagnostic::error("effect::duplicate", message)
                    .label(e.name.span, label)
                    .help("give the effect another name (explain leaves a built-in out with --without)"),
            );
        } else if let Some(first) = seen.iter().find(|s| s.node == e.name.node) {
            diags.push(
                Diagnostic::error(
                    "effect::duplicate",
                    format!("effect `{}` is defined twice", e.name.node),
                )
                .label(e.name.span, "defined again here")
                .label(first.span, "first defined here")
                .help("give each effect its own name"),
            );
        }
        seen.push(&e.name);
        if let Some(c) = effect_def(e, signals, &mut diags) {
            out.push(c);
        }
    }
    if diags.is_empty() {
        Ok(out)
    } else {
        Err(diags)
    }
}

fn effect_def(
    e: &EffectDef,
    signals: &[SignalDef],
    diags: &mut Vec<Diagnostic>,
) -> Option<Checked> {
    let before = diags.len();
    let mut explanation: Option<&Spanned<String>> = None;
    let mut follows: Option<&Spanned<String>> = None;
    let mut params: Vec<(String, Span)> = Vec::new();
    let mut decls = Vec::new();
    for item in &e.items {
        match item {
            EffectItem::Explanation(s) | EffectItem::Follows(s) => {
                let (slot, what) = match item {
                    EffectItem::Explanation(_) => (&mut explanation, "explanation"),
                    _ => (&mut follows, "follows"),
                };
                if let Some(first) = slot {
                    diags.push(
                        Diagnostic::error("effect::duplicate", format!("`{what}` given twice"))
                            .label(s.span, "again here")
                            .label(first.span, "first here")
                            .help(format!("keep one `{what}` per effect")),
                    );
                } else {
                    *slot = Some(s);
                }
            }
            EffectItem::Param(p) => {
                let name = &p.name.node;
                if let Some((_, first)) = params.iter().find(|(n, _)| n == name) {
                    diags.push(
                        Diagnostic::error(
                            "effect::duplicate",
                            format!("parameter `{name}` declared twice"),
                        )
                        .label(p.name.span, "declared again here")
                        .label(*first, "first declared here")
                        .help("give each parameter its own name"),
                    );
                } else if is_reserved(name, signals) {
                    diags.push(
                        Diagnostic::error(
                            "effect::name_taken",
                            format!("`{name}` is a signal, constant or function"),
                        )
                        .label(p.name.span, "cannot name a parameter")
                        .help("pick a parameter name that no signal, constant or function has (docs/user-effects.md lists them)"),
                    );
                }
                if p.needs.is_none() {
                    diags.push(
                        Diagnostic::error(
                            "effect::missing",
                            format!("parameter `{name}` does not say what motion excites it"),
                        )
                        .label(p.name.span, "no `needs \"...\"`")
                        .help("add e.g. `needs \"rotate about Z\"`: explain shows it when the recording cannot determine the parameter"),
                    );
                }
                params.push((name.clone(), p.name.span));
                decls.push(p);
            }
            EffectItem::Contribution(_) => {}
        }
    }
    let mut cx = Cx {
        params: &params,
        signals,
        used_params: BTreeSet::new(),
        used_signals: BTreeSet::new(),
        diags: Vec::new(),
    };
    let mut regs = Vec::new();
    let mut any_contribution = false;
    for item in &e.items {
        let EffectItem::Contribution(c) = item else {
            continue;
        };
        any_contribution = true;
        let channel = CHANNELS.iter().position(|(n, _)| *n == c.channel.node);
        if channel.is_none() {
            let names: Vec<&str> = CHANNELS.iter().map(|c| c.0).collect();
            cx.diags.push(
                Diagnostic::error(
                    "effect::unknown_channel",
                    format!("unknown output channel `{}`", c.channel.node),
                )
                .label(c.channel.span, "not an output channel")
                .help(format!(
                    "{}the channels are {}",
                    suggestion(&c.channel.node, names.iter().copied()),
                    names.join(" ")
                )),
            );
        }
        let (ex, class) = lin(&c.expr, &mut cx);
        if class == Class::Free {
            cx.diags.push(
                Diagnostic::error("effect::no_parameter", "this contribution holds no parameter")
                    .label(c.expr.span, "nothing here is fitted")
                    .help("multiply it by a parameter of the effect: the fit estimates parameters, not fixed terms"),
            );
        }
        if let (Some(ch), Class::Linear) = (channel, class) {
            for k in 0..params.len() {
                if let Some(r) = ex.d(k) {
                    regs.push(Reg {
                        param: k,
                        channel: ch,
                        ex: r,
                    });
                }
            }
        }
    }
    let used = std::mem::take(&mut cx.used_params);
    let used_signals = std::mem::take(&mut cx.used_signals);
    diags.extend(cx.diags);
    if explanation.is_none() {
        diags.push(
            Diagnostic::error(
                "effect::missing",
                format!("effect `{}` has no explanation", e.name.node),
            )
            .label(
                e.name.span,
                "explain shows an explanation for every finding",
            )
            .help(
                "add `explanation \"...\"`: the physics, in one line an engineer reads in a report",
            ),
        );
    }
    if !any_contribution || params.is_empty() {
        diags.push(
            Diagnostic::error(
                "effect::missing",
                format!("effect `{}` has no parameter or no contribution", e.name.node),
            )
            .label(e.name.span, "nothing to fit")
            .help("declare `param <name> unit \"...\" needs \"...\"` and add `<channel> += <expression>`"),
        );
    }
    for (k, (name, span)) in params.iter().enumerate() {
        if !used.contains(&k) && any_contribution {
            diags.push(
                Diagnostic::error(
                    "effect::unused_parameter",
                    format!("parameter `{name}` is not used"),
                )
                .label(*span, "no contribution reads it")
                .help("use it in a contribution or remove it: the fit could not determine it"),
            );
        }
    }
    if diags.len() > before {
        return None;
    }
    let follows = match follows {
        Some(f) => f.node.clone(),
        None => used_signals.into_iter().collect::<Vec<_>>().join(", "),
    };
    Some(Checked {
        id: e.name.clone(),
        explanation: explanation.map(|x| x.node.clone()).unwrap_or_default(),
        follows,
        params: decls
            .iter()
            .map(|p| {
                let needs = p.needs.as_ref().map(|n| n.node.clone()).unwrap_or_default();
                (p.name.node.clone(), p.unit.node.clone(), needs)
            })
            .collect(),
        regs,
    })
}

fn is_reserved(name: &str, signals: &[SignalDef]) -> bool {
    signals.iter().any(|s| s.name == name)
        || CONSTANTS.iter().any(|c| c.0 == name)
        || FUNCTIONS.iter().any(|f| f.0 == name)
}
