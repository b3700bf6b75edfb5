//! Segments: settle blocks, names with `{var}` interpolation, and the uniqueness rules.

use super::Ck;
use super::values::{Val, suggest};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{self, Block, Span};
use ratecal_plan::{Dim, OnTimeout, Settle, Signal, Stability};

impl Ck<'_> {
    pub(crate) fn settle(&mut self, b: &Block<ast::SettleItem>) -> Settle {
        let mut st = Settle {
            min_time_s: 0.0,
            stable: Vec::new(),
            attitude_error_deg: None,
            rate_error_dps: None,
            timeout_s: None,
            on_timeout: OnTimeout::Abort,
        };
        for item in &b.items {
            match &item.node {
                ast::SettleItem::AtLeast(v) => {
                    if let Some(q) = self.quantity(v, Dim::Time, "a settle time") {
                        st.min_time_s = q.value;
                    }
                }
                ast::SettleItem::Timeout(v, act) => {
                    if let Some(q) = self.quantity(v, Dim::Time, "a timeout") {
                        st.timeout_s = Some(q.value);
                    }
                    if let Some(a) = act {
                        st.on_timeout = match a.node.as_str() {
                            "abort" => OnTimeout::Abort,
                            "warn" => OnTimeout::Warn,
                            "continue" => OnTimeout::Continue,
                            other => {
                                self.err(
                                    Diagnostic::error(
                                        "check::unknown_name",
                                        format!("unknown timeout action `{other}`"),
                                    )
                                    .label(a.span, "not an action")
                                    .help(suggest(other, &["abort", "warn", "continue"])),
                                );
                                OnTimeout::Abort
                            }
                        };
                    }
                }
                ast::SettleItem::Fluctuation {
                    signal,
                    value,
                    window,
                    ..
                } => {
                    let (sig, dim) = match signal.node.as_str() {
                        "accel" => (Signal::Accel, Dim::Accel),
                        "gyro" => (Signal::Gyro, Dim::Rate),
                        other => {
                            self.err(
                                Diagnostic::error(
                                    "check::unknown_name",
                                    format!("unknown signal `{other}`"),
                                )
                                .label(signal.span, "no fluctuation limit on this signal")
                                .help(suggest(other, &["accel", "gyro"])),
                            );
                            continue;
                        }
                    };
                    let q = self.quantity(value, dim, "a fluctuation limit");
                    let w = self.quantity(window, Dim::Time, "a stability window");
                    if let (Some(q), Some(w)) = (q, w) {
                        st.stable.push(Stability {
                            signal: sig,
                            max_fluctuation: q.value,
                            window_s: w.value,
                        });
                    }
                }
                ast::SettleItem::Limit(l) => match l.name.node.as_str() {
                    "table.attitude_error" => {
                        st.attitude_error_deg = self
                            .quantity(&l.value, Dim::Angle, "an attitude error limit")
                            .map(|q| q.value)
                    }
                    "table.rate_error" => {
                        st.rate_error_dps = self
                            .quantity(&l.value, Dim::Rate, "a rate error limit")
                            .map(|q| q.value)
                    }
                    other => self.err(
                        Diagnostic::error(
                            "check::unknown_name",
                            format!("unknown settle condition `{other}`"),
                        )
                        .label(l.name.span, "not a settle condition")
                        .help(suggest(
                            other,
                            &[
                                "table.attitude_error",
                                "table.rate_error",
                                "accel fluctuation",
                                "gyro fluctuation",
                            ],
                        )),
                    ),
                },
            }
        }
        st
    }

    /// Expands `{var}` / `{var:+}` in a segment name; repeat indices stay as `{var}`.
    pub(crate) fn segment_id(&mut self, template: &str, span: Span) -> Option<String> {
        let mut out = String::new();
        let mut rest = template;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let Some(close) = rest[open..].find('}') else {
                self.err(
                    Diagnostic::error("check::bad_segment_name", "unclosed `{` in a segment name")
                        .label(span, "here")
                        .help("write `{name}` to insert a loop variable"),
                );
                return None;
            };
            let inner = &rest[open + 1..open + close];
            let (name, plus) = match inner.strip_suffix(":+") {
                Some(n) => (n, true),
                None => (inner, false),
            };
            if self.walk.repeats.iter().any(|(v, _)| v == name) {
                out.push_str(&rest[open..open + close + 1]);
            } else {
                let found = self
                    .scopes
                    .iter()
                    .rev()
                    .flat_map(|s| s.iter())
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| v.clone());
                match found.map(|v| v.v) {
                    Some(Val::Num { text, q }) => {
                        if plus && !text.starts_with(['+', '-']) {
                            out.push('+');
                        }
                        let _ = q;
                        out.push_str(&text);
                    }
                    Some(Val::Sym(s)) | Some(Val::Str(s)) => out.push_str(&s),
                    Some(_) => {
                        self.err(
                            Diagnostic::error(
                                "check::type_mismatch",
                                format!("`{name}` cannot go in a segment name"),
                            )
                            .label(span, "a list or tuple")
                            .help("insert a number or a name"),
                        );
                        return None;
                    }
                    None => {
                        let mut names: Vec<String> = self
                            .scopes
                            .iter()
                            .flatten()
                            .map(|(n, _)| n.clone())
                            .collect();
                        names.extend(self.walk.repeats.iter().map(|(v, _)| v.clone()));
                        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
                        self.err(
                            Diagnostic::error(
                                "check::unknown_name",
                                format!("unknown name `{name}` in a segment name"),
                            )
                            .label(span, "not a loop variable here")
                            .help(if refs.is_empty() {
                                "no loop variable is in scope here".to_string()
                            } else {
                                suggest(name, &refs)
                            }),
                        );
                        return None;
                    }
                }
            }
            rest = &rest[open + close + 1..];
        }
        out.push_str(rest);
        Some(out)
    }

    /// Duplicate segments, and segments inside repeats that do not use the index.
    pub(crate) fn finish_segments(&mut self) {
        let segs = std::mem::take(&mut self.walk.segments);
        let mut seen: std::collections::HashMap<&str, Span> = std::collections::HashMap::new();
        for s in &segs {
            for v in &s.repeats {
                if v.is_empty() || !s.id.contains(&format!("{{{v}}}")) {
                    self.err(
                        Diagnostic::error("check::segment_in_repeat", format!("segment `{}` would be recorded once per repetition under the same name", s.id))
                            .label(s.span, "inside a `repeat`")
                            .help("name the index (`repeat 3 as run`) and use it: \"name/{run}\""),
                    );
                }
            }
            if let Some(first) = seen.get(s.id.as_str()) {
                let mut d = Diagnostic::error(
                    "check::duplicate_segment",
                    format!("segment `{}` is recorded twice", s.id),
                )
                .label(s.span, "recorded again here");
                if *first != s.span {
                    d = d.label(*first, "first recorded here");
                }
                self.err(d.help(
                    "segment names must be unique: insert a loop variable, e.g. \"name/{n}\"",
                ));
            } else {
                seen.insert(&s.id, s.span);
            }
        }
        self.walk.segments = segs;
    }
}
