//! Paths in the commands a help line suggests (`ratecal verify RUN`), written so that
//! pasting the command into a POSIX shell passes the path as one word: a folder named
//! `runs/cal 1` or `it's` stays itself.

use std::path::Path;

/// `path` as one shell word: as it is when nothing in it needs quoting, else quoted.
pub fn quoted(path: &Path) -> String {
    let s = path.to_string_lossy();
    match shlex::try_quote(&s) {
        Ok(q) => q.into_owned(),
        // A NUL byte cannot be passed at all; shown as it is.
        Err(_) => s.into_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::quoted;
    use std::path::Path;

    #[test]
    fn plain_paths_stay_and_others_are_one_word() {
        assert_eq!(quoted(Path::new("runs/cal1")), "runs/cal1");
        for odd in ["runs/cal 1", "it's", "a;rm -rf b", "$HOME/x", "*"] {
            let q = quoted(Path::new(odd));
            assert_ne!(q, odd);
            assert_eq!(shlex::split(&q), Some(vec![odd.to_string()]), "{q}");
        }
    }
}
