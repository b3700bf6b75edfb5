//! `ratecal explain --draft-effects` from the command line, on the shared bias-step
//! recording written by an independent implementation of the spec (no registry effect
//! holds a bias step): the step is discovered, its draft effect file is written, and read
//! back with `--effects` it is named from that file with the same values.

use crate::support;
use std::process::{Command, Output};
use support::text;

fn ratecal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .env_remove("RATECAL_EFFECTS")
        .output()
        .unwrap()
}

fn k(f: &serde_json::Value, name: &str) -> (f64, f64) {
    let p = &f["parameters"][name];
    (p["value"].as_f64().unwrap(), p["u"].as_f64().unwrap())
}

#[test]
fn a_discovered_step_is_drafted_and_confirmed_from_its_file() {
    let Some(ex) = support::shared_example("open-accel-bias-step") else {
        return;
    };
    let ex = ex.to_str().unwrap();
    let drafts = tempfile::tempdir().unwrap();
    let dir = drafts.path().to_str().unwrap();
    let o = ratecal(&["explain", ex, "--draft-effects", dir, "--format", "json"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let found: Vec<&serde_json::Value> = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["discovered"] == true)
        .collect();
    assert_eq!(found.len(), 1, "{}", text(&o));
    let step = found[0];
    let id = step["effect"].as_str().unwrap();
    assert!(id.starts_with("discovered_ax_ay_step_"), "{id}");
    let file = drafts.path().join(format!("{id}.effect"));
    assert!(file.is_file(), "no draft at {}", file.display());
    assert_eq!(v["draft_effects"][0]["file"], file.display().to_string());
    let o = ratecal(&["explain", ex, "--effects", dir, "--format", "json"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let w: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let again = w["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["effect"] == id)
        .unwrap_or_else(|| panic!("{id} not confirmed: {}", text(&o)));
    assert_eq!(again["defined_in"], file.display().to_string());
    assert_eq!(again["discovered"], false);
    for name in ["k_ax", "k_ay"] {
        let (a, ua) = k(step, name);
        let (b, _) = k(again, name);
        assert!(
            (a - b).abs() <= ua,
            "{name}: {a} +- {ua} discovered, {b} from the draft"
        );
    }
    assert!(
        w["findings"]
            .as_array()
            .unwrap()
            .iter()
            .all(|f| f["discovered"] == false),
        "nothing left to discover"
    );
}
