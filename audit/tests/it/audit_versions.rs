//! Rules of a procedure folder and its versions.lock.

use ratecal_audit::versions::{
    FolderData, Version, VersionFile, check_versions, parse_lock, render_lock,
};

const H1: &str = "1111111111111111111111111111111111111111111111111111111111111111";
const H2: &str = "2222222222222222222222222222222222222222222222222222222222222222";
const H3: &str = "3333333333333333333333333333333333333333333333333333333333333333";

fn file(version: &str, declared: &str, sha: &str) -> VersionFile {
    VersionFile {
        path: format!("procs/p/{version}.rcal"),
        file_name: format!("{version}.rcal"),
        text: format!("procedure p version {declared} {{ }}\n"),
        declared: Some(declared.into()),
        sha256: Some(sha.into()),
    }
}

fn folder(files: Vec<VersionFile>, lock: &[(&str, &str)]) -> FolderData {
    let entries: Vec<(String, String)> = lock
        .iter()
        .map(|(v, h)| (v.to_string(), h.to_string()))
        .collect();
    FolderData {
        path: "procs/p".into(),
        files,
        lock: Some(render_lock(&entries)),
        others: vec![],
    }
}

fn codes(f: &FolderData) -> Vec<String> {
    check_versions(f)
        .iter()
        .map(|d| d.code.to_string())
        .collect()
}

#[test]
fn semantic_versions_order_numerically() {
    let v = |s| Version::parse(s).unwrap();
    assert!(v("1.10.0") > v("1.9.0"));
    assert!(v("2.0.0") > v("1.99.99"));
    assert!(v("1.1.0-rc.1") < v("1.1.0"));
    assert!(v("1.0.1") > v("1.0.0"));
    for bad in ["1.0", "1.0.0.0", "01.0.0", "a.b.c", "1.0.0-", ""] {
        assert!(Version::parse(bad).is_none(), "{bad}");
    }
}

#[test]
fn a_consistent_folder_is_clean() {
    let f = folder(
        vec![file("1.0.0", "1.0.0", H1), file("1.1.0", "1.1.0", H2)],
        &[("1.0.0", H1), ("1.1.0", H2)],
    );
    assert!(codes(&f).is_empty(), "{:?}", codes(&f));
}

#[test]
fn a_released_version_that_changed_is_refused() {
    let f = folder(
        vec![file("1.0.0", "1.0.0", H3), file("1.1.0", "1.1.0", H2)],
        &[("1.0.0", H1), ("1.1.0", H2)],
    );
    let d = check_versions(&f);
    assert_eq!(codes(&f), vec!["versions::released_changed"]);
    assert!(d[0].message.contains("1.0.0"));
    assert!(
        d[0].help.as_deref().unwrap().contains(H3),
        "help gives the new hash"
    );
}

#[test]
fn versions_that_do_not_increase_are_refused() {
    // lock out of order
    let f = folder(
        vec![file("1.0.0", "1.0.0", H1), file("1.1.0", "1.1.0", H2)],
        &[("1.1.0", H2), ("1.0.0", H1)],
    );
    assert_eq!(codes(&f), vec!["versions::not_increasing"]);
    // a new file below the last release
    let f = folder(
        vec![
            file("1.0.0", "1.0.0", H1),
            file("1.1.0", "1.1.0", H2),
            file("1.0.5", "1.0.5", H3),
        ],
        &[("1.0.0", H1), ("1.1.0", H2)],
    );
    assert_eq!(codes(&f), vec!["versions::not_increasing"]);
    // the same version twice
    let f = folder(
        vec![file("1.0.0", "1.0.0", H1)],
        &[("1.0.0", H1), ("1.0.0", H1)],
    );
    assert_eq!(codes(&f), vec!["versions::not_increasing"]);
}

#[test]
fn a_new_unreleased_version_is_a_warning() {
    let f = folder(
        vec![file("1.0.0", "1.0.0", H1), file("1.2.0", "1.2.0", H3)],
        &[("1.0.0", H1)],
    );
    let d = check_versions(&f);
    assert_eq!(codes(&f), vec!["versions::unreleased"]);
    assert!(!d[0].is_error());
}

#[test]
fn missing_release_mismatched_name_stray_file_bad_line() {
    let mut f = folder(vec![file("1.1.0", "1.2.0", H2)], &[("1.0.0", H1)]);
    f.others.push("notes.txt".into());
    f.lock = Some(format!("{}garbage line\n", f.lock.unwrap()));
    let c = codes(&f);
    for code in [
        "versions::stray_file",
        "versions::name_mismatch",
        "versions::bad_lock_line",
        "versions::release_missing",
    ] {
        assert!(c.contains(&code.to_string()), "{code} in {c:?}");
    }
}

#[test]
fn lock_round_trip_and_spans() {
    let text = render_lock(&[("1.0.0".into(), H1.into())]);
    let (entries, errors) = parse_lock("versions.lock", &text);
    assert!(errors.is_empty());
    assert_eq!(entries[0].sha256, H1);
    let (s, len) = entries[0].span;
    assert_eq!(&text[s..s + len], format!("1.0.0 {H1}"));
    let (_, errors) = parse_lock("versions.lock", "1.0.0 ABC\n");
    assert_eq!(errors.len(), 1);
}
