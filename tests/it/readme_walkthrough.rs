//! README.md runs as written. Every command of every `sh` block, in the README's order, runs
//! in one temporary copy of the repository's procedures, stations, templates and docs, with
//! the binary this build made (the release binary in CI) as `ratecal`: the main job, the
//! lever arm found, adopted as a new procedure version, checked, diffed, released and run,
//! the certificate, the imports of the real sessions, the manual station, the twin. So a
//! walkthrough, an exit code or an excerpt in the README cannot go stale.
//!
//! What the test reads in README.md:
//! - `cargo run --release -- ARGS`, `target/release/ratecal ARGS` and `ratecal ARGS` are the
//!   binary; `cargo build`, `cargo test` and `alias` lines are the reader's, not run;
//! - a trailing `# exit N` (or `# exit 0 or 1`) is the command's exit code, otherwise 0;
//! - a ```` ```text ```` block is an excerpt of what the preceding `sh` block's last command
//!   printed: each of its lines is a line of that output (a line ending in `...` its
//!   beginning; `...` alone stands for lines left out).
//!
//! Every command's output must also hold the line its subcommand always prints
//! ([`key_line`]). Commands that read `../shared/` are skipped, with the rest of their
//! block, where this machine lacks it.

use crate::support;
use std::path::Path;
use std::process::Command;

/// One fenced block of README.md.
struct Block {
    info: String,
    /// 1-based line of the opening fence.
    line: usize,
    body: Vec<String>,
}

/// One command of an `sh` block.
#[derive(Debug)]
struct Cmd {
    line: usize,
    /// The shell text with the binary as `ratecal` and the trailing comment removed.
    text: String,
    exits: Vec<i32>,
}

fn blocks(md: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, l) in md.lines().enumerate() {
        match (l.strip_prefix("```"), open.take()) {
            (Some(_), Some(b)) => out.push(b),
            (Some(info), None) => {
                open = Some(Block {
                    info: info.trim().to_string(),
                    line: i + 1,
                    body: Vec::new(),
                })
            }
            (None, Some(mut b)) => {
                b.body.push(l.to_string());
                open = Some(b);
            }
            (None, None) => {}
        }
    }
    out
}

/// The commands of an `sh` block: continuation lines joined, comments and the reader's own
/// lines (build, test, alias) left out.
fn commands(b: &Block) -> Vec<Cmd> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in b.body.iter().enumerate() {
        let (start, mut text) = pending.take().unwrap_or((b.line + 1 + i, String::new()));
        let l = raw.trim();
        if let Some(head) = l.strip_suffix('\\') {
            text.push_str(head.trim());
            text.push(' ');
            pending = Some((start, text));
            continue;
        }
        text.push_str(l);
        let readers = ["cargo build", "cargo test", "alias "];
        if text.is_empty() || text.starts_with('#') || readers.iter().any(|r| text.starts_with(r)) {
            continue;
        }
        out.push(command(start, &text));
    }
    out
}

fn command(line: usize, text: &str) -> Cmd {
    let (shell, comment) = match text.find(" #") {
        Some(k) => (&text[..k], text[k + 2..].trim()),
        None => (text, ""),
    };
    let mut shell = shell.trim().to_string();
    for bin in ["cargo run --release -- ", "target/release/ratecal "] {
        shell = shell.replace(bin, "ratecal ");
    }
    Cmd {
        line,
        text: shell,
        exits: exits(comment),
    }
}

/// `exit 1`, `exit 0 or 1: why` -> the codes; no such comment -> 0.
fn exits(comment: &str) -> Vec<i32> {
    let Some(rest) = comment.strip_prefix("exit ") else {
        return vec![0];
    };
    let codes: Vec<i32> = rest
        .split([':', '('])
        .next()
        .unwrap_or("")
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(
        !codes.is_empty(),
        "README: `# {comment}` names no exit code"
    );
    codes
}

/// What a subcommand always prints (standard output or error), one of these.
fn key_line(cmd: &str) -> &'static [&'static str] {
    let last = cmd.rsplit('|').next().unwrap_or(cmd).trim();
    let mut words = last.split_whitespace();
    match (words.next(), words.next()) {
        (Some("ratecal"), Some("run")) => &["sealed: "],
        (Some("ratecal"), Some("explain")) => &["nominal model"],
        (Some("ratecal"), Some("check")) => &[": ok"],
        (Some("ratecal"), Some("diff")) => &["change(s)"],
        (Some("ratecal"), Some("key")) => &["public key:", "already holds a key"],
        (Some("ratecal"), Some("release")) => &["released "],
        (Some("ratecal"), Some("approve")) => &["approved: "],
        (Some("ratecal"), Some("archive")) => &["archived "],
        (Some("ratecal"), Some("certificate")) => &["certificate"],
        (Some("ratecal"), Some("import")) => &["imported "],
        (Some("ratecal"), Some("analyze")) => &["verdict"],
        (Some("patch"), _) => &["patching file"],
        _ => &[""],
    }
}

/// The temporary repository: copies of what the commands read or change, `../shared`
/// beside it when this machine has it, and `ratecal` on the path.
fn workspace(tmp: &Path) -> (std::path::PathBuf, bool) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let repo = tmp.join("repo");
    for dir in ["procedures", "drivers/stations", "templates", "docs"] {
        copy_dir(&root.join(dir), &repo.join(dir));
    }
    let bin = tmp.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_ratecal"), bin.join("ratecal")).unwrap();
    let shared = support::shared_path("");
    if let Some(s) = &shared {
        std::os::unix::fs::symlink(s, tmp.join("shared")).unwrap();
    }
    (repo, shared.is_some())
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        match e.file_type().unwrap().is_dir() {
            true => copy_dir(&e.path(), &to.join(e.file_name())),
            false => {
                std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
            }
        }
    }
}

/// Runs `cmd` in `repo`: its exit code and what it printed, both streams.
fn run(repo: &Path, cmd: &Cmd) -> (i32, String) {
    let bin = repo.parent().unwrap().join("bin");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut c = Command::new("sh");
    c.args(["-c", &cmd.text])
        .current_dir(repo)
        .env("PATH", path);
    for (k, _) in std::env::vars().filter(|(k, _)| k.starts_with("RATECAL_")) {
        c.env_remove(k);
    }
    let o = c.output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.code().unwrap_or(-1), text)
}

/// Each line of the excerpt is a line of `output` (trimmed; `...` ending a line: its
/// beginning). The lines that are not, with where.
fn missing(excerpt: &Block, output: &str) -> Vec<String> {
    let lines: Vec<&str> = output.lines().map(str::trim).collect();
    let mut out = Vec::new();
    for (i, l) in excerpt.body.iter().enumerate() {
        let l = l.trim();
        if l.is_empty() || l == "..." {
            continue;
        }
        let found = match l.strip_suffix("...") {
            Some(head) => lines.iter().any(|o| o.starts_with(head.trim_end())),
            None => lines.contains(&l),
        };
        if !found {
            out.push(format!("README.md:{}: {l}", excerpt.line + 1 + i));
        }
    }
    out
}

#[test]
fn every_command_and_excerpt_of_the_readme_holds() {
    let md =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let (repo, has_shared) = workspace(tmp.path());
    let mut failures = Vec::new();
    // The last command's output (None: skipped), for the excerpt that follows its block.
    let mut last: Option<String> = None;
    let (mut ran, mut excerpts) = (0, 0);
    for b in blocks(&md) {
        match b.info.as_str() {
            "sh" => {
                last = None;
                for cmd in commands(&b) {
                    if cmd.text.contains("../shared") && !has_shared {
                        println!("skipped: README.md:{} reads ../shared", cmd.line);
                        break;
                    }
                    let (code, out) = run(&repo, &cmd);
                    ran += 1;
                    let keys = key_line(&cmd.text);
                    if !cmd.exits.contains(&code) || !keys.iter().any(|k| out.contains(k)) {
                        failures.push(format!(
                            "README.md:{}: `{}` exited {code} (README: {:?}), wants one of \
                             {keys:?} in its output:\n{out}",
                            cmd.line, cmd.text, cmd.exits
                        ));
                    }
                    last = Some(out);
                }
            }
            "text" => match &last {
                Some(out) => {
                    excerpts += 1;
                    let lost = missing(&b, out);
                    if !lost.is_empty() {
                        failures.push(format!(
                            "README.md:{}: excerpt lines not printed:\n{}\n--- the output:\n{out}",
                            b.line,
                            lost.join("\n")
                        ));
                    }
                }
                None => println!("skipped: README.md:{}: its command was skipped", b.line),
            },
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    // The walkthrough itself: the main job, explain, adoption, certificate, twin.
    assert!(ran >= 20, "only {ran} README commands ran");
    assert!(excerpts >= 3, "only {excerpts} README excerpts checked");
}

#[test]
fn the_readme_conventions_read_as_documented() {
    let b = Block {
        info: "sh".into(),
        line: 10,
        body: vec![
            "cargo build --release".into(),
            "# a comment".into(),
            "ratecal import a.csv \\".into(),
            "    --map m.yaml --out r".into(),
            "cargo run --release -- diff a b   # exit 1: changes".into(),
            "target/release/ratecal key new k   # exit 0 or 1: when k holds one".into(),
        ],
    };
    let c = commands(&b);
    assert_eq!(c.len(), 3, "{c:?}");
    assert_eq!(c[0].text, "ratecal import a.csv --map m.yaml --out r");
    assert_eq!((c[0].line, c[0].exits.as_slice()), (13, &[0][..]));
    assert_eq!(
        (c[1].text.as_str(), c[1].exits.as_slice()),
        ("ratecal diff a b", &[1][..])
    );
    assert_eq!(c[2].exits, vec![0, 1]);
    let excerpt = Block {
        info: "text".into(),
        line: 1,
        body: vec!["  a line".into(), "...".into(), "begins...".into()],
    };
    assert!(missing(&excerpt, "x\n a line \nbegins here\n").is_empty());
    assert_eq!(missing(&excerpt, "a line\nbegin").len(), 1);
}
