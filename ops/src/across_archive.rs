//! `ratecal explain --archive A --serial SN | --model M [--since D] [--until D]`: the runs
//! of one unit's history, or of every unit of a model, from the archive (SQLite or
//! PostgreSQL alike), explained and pooled as `explain RUN RUN...` pools folders. Each
//! run's explanation is kept in the archive beside the run (`explained`), so a second query
//! over the same runs exports and explains none of them again: only the pooling is
//! computed.

use crate::across::{Context, Explained, explain_all};
use ratecal_archive::{Archive, Filter, Location, RunSummary};

/// Which archived runs to explain.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// `--archive` (a folder or a `postgres://` URL); `None`: `RATECAL_ARCHIVE`, else
    /// `./archive/`.
    pub archive: Option<String>,
    /// One unit's history.
    pub serial: Option<String>,
    /// Every unit of a model.
    pub model: Option<String>,
    /// Started at or after.
    pub since: Option<String>,
    /// Started at or before (a bare date includes the day).
    pub until: Option<String>,
    /// Dry runs too (hidden by default, as in `archive list`).
    pub include_dry_runs: bool,
}

/// A command that stops with this exit code, its diagnostics said.
type Exit = u8;

/// The selected runs explained (kept explanations read back, the others explained and
/// kept), oldest first; `key` names the analysis (version and options).
pub fn explained(sel: &Selection, cx: &Context, key: &str) -> Result<Vec<Explained>, Exit> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| {
            errln!("error: cannot start the archive's runtime: {e}");
            2u8
        })?;
    rt.block_on(async {
        let loc = Location::resolve(sel.archive.as_deref(), None);
        let archive = Archive::open_existing(&loc).await.map_err(say)?;
        let runs = archive.list(&filter(sel)).await.map_err(say)?;
        if runs.is_empty() {
            let e = miette::miette!(
                code = "explain::no_runs",
                help = "`ratecal archive list` with the same --serial/--model/--since/--until \
                        shows what the archive holds (dry runs need --include-dry-runs)",
                "no archived run of {} matches in {}",
                sel.serial
                    .as_deref()
                    .map(|s| format!("serial {s}"))
                    .or(sel.model.as_deref().map(|m| format!("model {m}")))
                    .unwrap_or_else(|| "any unit".into()),
                loc.display()
            );
            errln!("{e:?}");
            return Err(2);
        }
        let out = explain_runs(&archive, &runs, cx, key).await;
        archive.close().await;
        out
    })
}

fn say(e: ratecal_archive::ArchiveError) -> Exit {
    errln!("{:?}", miette::Report::new(e));
    2
}

fn filter(sel: &Selection) -> Filter {
    Filter {
        serial: sel.serial.clone(),
        model: sel.model.clone(),
        since: sel.since.clone(),
        until: sel.until.clone(),
        include_dry_runs: sel.include_dry_runs,
        ..Filter::default()
    }
}

/// Every run's explanation: the kept ones read back, the rest exported a few at a time
/// into a scratch folder, explained in parallel and kept.
async fn explain_runs(
    archive: &Archive,
    runs: &[RunSummary],
    cx: &Context,
    key: &str,
) -> Result<Vec<Explained>, Exit> {
    let mut slots: Vec<Option<Explained>> = Vec::new();
    for r in runs {
        let kept = archive.explained(&r.id, key).await.map_err(say)?;
        slots.push(kept.and_then(|body| parse(&body)).map(|mut x| {
            x.run = name_of(r);
            x
        }));
    }
    let todo: Vec<usize> = (0..runs.len()).filter(|&i| slots[i].is_none()).collect();
    errln!(
        "{} archived run(s): {} explanation(s) kept in the archive, {} to explain",
        runs.len(),
        runs.len() - todo.len(),
        todo.len()
    );
    let batch = 2 * std::thread::available_parallelism().map_or(1, |n| n.get());
    let scratch = std::env::temp_dir().join(format!("ratecal-explain-{}", std::process::id()));
    for chunk in todo.chunks(batch) {
        let mut jobs = Vec::new();
        for &i in chunk {
            let dir = scratch.join(&runs[i].id);
            std::fs::remove_dir_all(&dir).ok();
            if let Err(e) = archive.export(&runs[i].id, &dir).await {
                std::fs::remove_dir_all(&scratch).ok();
                return Err(say(e));
            }
            jobs.push((name_of(&runs[i]), dir));
        }
        let done = explain_all(&jobs, cx);
        std::fs::remove_dir_all(&scratch).ok();
        for (&i, x) in chunk.iter().zip(done?) {
            let body = serde_json::json!({
                "serial": x.serial,
                "model": x.model,
                "explanation": x.explanation,
            });
            if let Err(e) = archive
                .keep_explained(&runs[i].id, key, &body.to_string())
                .await
            {
                errln!(
                    "warning: the explanation of {} is not kept in the archive: {e}",
                    runs[i].id
                );
            }
            slots[i] = Some(x);
        }
    }
    Ok(slots.into_iter().flatten().collect())
}

/// A run as the output names it: its own name and its archive id (the id alone for a
/// recording without a name).
fn name_of(r: &RunSummary) -> String {
    match r.name.is_empty() {
        true => r.id.clone(),
        false => format!("{} ({})", r.name, r.id),
    }
}

/// A kept explanation (`None`: unreadable, explained again).
fn parse(body: &str) -> Option<Explained> {
    let v: serde_json::Value = serde_json::from_str(body).ok()?;
    Some(Explained {
        run: String::new(),
        serial: v["serial"].as_str()?.to_string(),
        model: v["model"].as_str()?.to_string(),
        explanation: serde_json::from_value(v["explanation"].clone()).ok()?,
    })
}

/// The analysis a kept explanation is valid for: the ratecal version, and the options
/// that change the result (the procedure's name, version and resolved content, so that a
/// text changed under one version with `--allow-changed` is explained again; the user
/// effects' files and texts, the effects left out).
pub fn key(cx: &Context, effects: &[(String, String)]) -> String {
    let mut s = format!("ratecal {}\n", env!("CARGO_PKG_VERSION"));
    if let Some(p) = &cx.plan {
        let content = serde_json::to_string(p).unwrap_or_default();
        s.push_str(&format!(
            "procedure {} {} {}\n",
            p.name,
            p.version,
            ratecal_folder::hashes::sha256_hex(content.as_bytes())
        ));
    }
    for (file, text) in effects {
        s.push_str(&format!("effect {file}\n{text}\n"));
    }
    for w in &cx.without {
        s.push_str(&format!("without {w}\n"));
    }
    ratecal_folder::hashes::sha256_hex(s.as_bytes())
}
