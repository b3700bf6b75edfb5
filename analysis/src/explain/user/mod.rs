//! User effects: candidate effects an engineer writes in `*.effect` files, tried by
//! explain like the registry's own (docs/user-effects.md). The grammar crate parses a
//! file; [`check`] resolves its names against the kinematic [`signals`] and proves each
//! contribution linear in the parameters; each parameter's regressor is the
//! contribution's symbolic derivative with respect to it ([`expr`]).

mod check;
mod effect;
mod expr;
mod linear;
mod signals;

pub use effect::UserEffect;
pub use signals::{CHANNELS, CONSTANTS, FUNCTIONS, SignalDef, signals};

use ratecal_grammar::{Diagnostic, source};

/// Parses and checks effect files (`(name, text)`, the name as diagnostics show it) and
/// makes their effects live for the process. Every error of every file at once; an id
/// defined in two files, or one of the registry's, is an error.
pub fn load(files: &[(String, String)]) -> Result<Vec<&'static UserEffect>, Vec<Diagnostic>> {
    let sigs = signals();
    let mut taken: Vec<(String, Option<String>)> = ratecal_physics::REGISTRY
        .iter()
        .map(|e| (e.id().to_string(), None))
        .collect();
    let mut diags = Vec::new();
    let mut checked = Vec::new();
    for (name, text) in files {
        let src = source(name, text);
        let file = match ratecal_grammar::effect::parse(text) {
            Ok(f) => f,
            Err(d) => {
                diags.push(d.with_source(&src));
                continue;
            }
        };
        let taken_now: Vec<(&str, Option<&str>)> = taken
            .iter()
            .map(|(id, f)| (id.as_str(), f.as_deref()))
            .collect();
        match check::check(&file, &sigs, &taken_now) {
            Ok(effects) => {
                for c in effects {
                    taken.push((c.id.node.clone(), Some(name.clone())));
                    checked.push((c, name));
                }
            }
            Err(ds) => diags.extend(ds.into_iter().map(|d| d.with_source(&src))),
        }
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    Ok(checked
        .into_iter()
        .map(|(c, name)| UserEffect::leak(c, name))
        .collect())
}

#[cfg(test)]
mod tests;
