//! The sealed run folder: every file is in the seal, each kind of tampering is caught by
//! `verify`, a signed seal defeats a forger who recomputes every hash, files ratecal adds
//! later join the seal, and `--resume` refuses a folder whose inputs changed.

use crate::support;
use support::*;

use ratecal_folder::hashes::sha256_hex;
use ratecal_folder::seal::Seal;
use std::path::Path;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

fn edit(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from} not in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn every_kind_of_tampering_is_caught() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let run = tmp.path().join("r");
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let seal = json(&run.join("seal.json"));
    for f in [
        "manifest.yaml",
        "results.json",
        "report.md",
        "journal.jsonl",
        "plan.json",
    ] {
        assert!(seal["files"].get(f).is_some(), "{f} not sealed: {seal}");
    }

    type Tamper = fn(&Path);
    let cases: [(&str, Tamper, &str); 10] = [
        (
            "manifest",
            |d| edit(&d.join("manifest.yaml"), "dry_run: true", "dry_run: false"),
            "manifest.yaml",
        ),
        (
            "verdict",
            |d| {
                edit(
                    &d.join("results.json"),
                    "\"verdict\": \"not_judged\"",
                    "\"verdict\": \"pass\"",
                )
            },
            "results.json",
        ),
        (
            "report",
            |d| edit(&d.join("report.md"), "DRY RUN", "REAL RUN"),
            "report.md",
        ),
        (
            "journal",
            |d| std::fs::write(d.join("journal.jsonl"), "").unwrap(),
            "journal.jsonl",
        ),
        (
            "plan",
            |d| std::fs::remove_file(d.join("plan.json")).unwrap(),
            "plan.json: missing",
        ),
        (
            "extra file",
            |d| std::fs::write(d.join("notes.txt"), "x").unwrap(),
            "notes.txt: not in the seal",
        ),
        (
            "seal edited",
            |d| edit(&d.join("seal.json"), "\"files\"", "\"files\" "),
            "seal.json (its hash",
        ),
        (
            "seal hash",
            |d| {
                std::fs::write(
                    d.join("seal.sha256"),
                    format!("{}  seal.json\n", "0".repeat(64)),
                )
                .unwrap()
            },
            "seal.json (its hash",
        ),
        (
            "seal missing",
            |d| std::fs::remove_file(d.join("seal.json")).unwrap(),
            "seal.json: missing",
        ),
        (
            "seal malformed",
            |d| std::fs::write(d.join("seal.json"), "{").unwrap(),
            "seal.json: no longer parses",
        ),
    ];
    for (what, tamper, named) in cases {
        let copy = tmp.path().join(format!("t-{}", what.replace(' ', "-")));
        copy_dir(&run, &copy);
        assert_eq!(
            code(&ratecal(&["verify", copy.to_str().unwrap()], tmp.path())),
            0
        );
        tamper(&copy);
        let o = ratecal(&["verify", copy.to_str().unwrap()], tmp.path());
        assert_eq!(code(&o), 1, "{what}: {}", text(&o));
        assert!(text(&o).contains(named), "{what}: {}", text(&o));
    }
}

#[test]
fn a_signed_seal_catches_a_forger_who_recomputes_every_hash() {
    let tmp = tempfile::tempdir().unwrap();
    let o = ratecal(&["key", "new", "keys"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(
        code(&ratecal(&["key", "new", "keys"], tmp.path())),
        1,
        "never overwritten"
    );
    let o = mini_run(tmp.path(), "r", &["--sign", "keys/lab.key"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["verify", "r", "--key", "keys/lab.pub"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    // Another lab's key does not vouch for this seal.
    assert_eq!(code(&ratecal(&["key", "new", "other"], tmp.path())), 0);
    let o = ratecal(&["verify", "r", "--key", "other/lab.pub"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));

    // The forger edits imu.csv and recomputes the manifest's hash, the seal and its hash.
    let run = tmp.path().join("r");
    let imu = std::fs::read_to_string(run.join("imu.csv")).unwrap();
    let line = imu.lines().nth(1).unwrap().to_string();
    let forged = imu.replacen(&line, &line.replacen('0', "1", 1), 1);
    std::fs::write(run.join("imu.csv"), &forged).unwrap();
    let old = sha256_hex(imu.as_bytes());
    edit(
        &run.join("manifest.yaml"),
        &old,
        &sha256_hex(forged.as_bytes()),
    );
    let mut seal: Seal =
        serde_json::from_str(&std::fs::read_to_string(run.join("seal.json")).unwrap()).unwrap();
    for name in ["imu.csv", "manifest.yaml"] {
        let bytes = std::fs::read(run.join(name)).unwrap();
        seal.files.insert(name.into(), sha256_hex(&bytes));
    }
    let text_json = seal.to_json();
    std::fs::write(run.join("seal.json"), &text_json).unwrap();
    std::fs::write(run.join("seal.sha256"), Seal::hash_line(&text_json)).unwrap();

    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(
        code(&o),
        0,
        "without a key the forgery is consistent: {}",
        text(&o)
    );
    let o = ratecal(&["verify", "r", "--key", "keys/lab.pub"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("signature does not match"),
        "{}",
        text(&o)
    );
}

#[test]
fn files_ratecal_adds_later_join_the_seal() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(code(&mini_run(tmp.path(), "r", &[])), 0);
    let o = ratecal(
        &["report", "r", "--format", "html", "--out", "r/report.html"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["analyze", "r", "--out", "r/again.json"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains("again.json (written by `ratecal analyze r --out r/again.json` at"),
        "{}",
        text(&o)
    );
}

#[test]
fn resume_refuses_a_folder_whose_inputs_changed() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("st.yaml"), station_with(EXCURSION)).unwrap();
    let o = mini_run(tmp.path(), "r", &["--station", "st.yaml"]);
    assert_eq!(code(&o), 4, "{}", text(&o));
    let run = tmp.path().join("r");
    let m = std::fs::read_to_string(run.join("manifest.yaml")).unwrap();
    let copy = tmp.path().join("r2");
    copy_dir(&run, &copy);
    let copy3 = tmp.path().join("r3");
    copy_dir(&run, &copy3);

    // A limit loosened in the run's procedure copy (seal and its hash rewritten too, so
    // that only the recorded procedure hash stands in the way).
    edit(&run.join("procedure.rcal"), "<= 5 arcsec", "<= 50 arcsec");
    let files = std::fs::read_dir(&run).unwrap().count();
    std::fs::remove_file(run.join("seal.json")).unwrap();
    std::fs::remove_file(run.join("seal.sha256")).unwrap();
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    let err = text(&o);
    assert!(err.contains("procedure.rcal: recorded sha256"), "{err}");
    let recorded = ratecal_recording::parse_manifest("manifest.yaml", &m)
        .unwrap()
        .procedure
        .unwrap()
        .sha256;
    assert!(err.contains(&recorded), "names the recorded hash: {err}");
    assert_eq!(
        std::fs::read_dir(&run).unwrap().count(),
        files - 2,
        "nothing written"
    );

    // The station file, likewise.
    std::fs::remove_file(copy.join("seal.json")).unwrap();
    edit(&copy.join("station.yaml"), "delta: 4 degC", "delta: 1 degC");
    let o = ratecal(&["run", "--resume", "r2"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("station.yaml: recorded sha256"),
        "{}",
        text(&o)
    );

    // A sealed folder edited anywhere is not resumed either.
    edit(&copy3.join("journal.jsonl"), "\"t\":", "\"t\": ");
    let o = ratecal(&["run", "--resume", "r3"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("journal.jsonl"), "{}", text(&o));
}

/// A help line's command names the folder as one shell word: a run folder whose name holds
/// a space and a quote is quoted, so the suggested `ratecal verify ...` pastes as it reads.
#[test]
fn help_commands_quote_the_folder_they_name() {
    let tmp = tempfile::tempdir().unwrap();
    let out = "it's run 1";
    let o = mini_run(tmp.path(), out, &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let run = tmp.path().join(out);
    edit(&run.join("manifest.yaml"), "imu:", "imu:   ");
    let into = format!("{out}/results.json");
    let o = ratecal(&["analyze", out, "--out", &into], tmp.path());
    let err = text(&o);
    assert_eq!(code(&o), 4, "{err}");
    let quoted = ratecal_folder::shell::quoted(Path::new(out));
    assert_eq!(shlex::split(&quoted), Some(vec![out.to_string()]));
    assert!(
        err.replace('\n', " ")
            .contains(&format!("`ratecal verify {quoted}`")),
        "{err}"
    );
}
