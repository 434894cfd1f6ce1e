//! Text files read leniently: a byte that is not UTF-8 (a Latin-1 `é` in a comment, a name
//! written on another system) is read as U+FFFD rather than rejecting the whole file. Where
//! it matters (in a number or a keyword) the reader then reports it, located; where it does
//! not (a comment, a name), the file reads, with a warning that names the first such place.

use crate::diagnostics::SceneError;
use std::path::Path;

/// A file's text, and a warning at its first byte that is not UTF-8 if it has one.
pub fn read_lenient(path: &Path) -> std::io::Result<(String, Option<String>)> {
    Ok(lenient(path, std::fs::read(path)?))
}

/// [`read_lenient`] of bytes already read.
pub fn lenient(path: &Path, bytes: Vec<u8>) -> (String, Option<String>) {
    match String::from_utf8(bytes) {
        Ok(text) => (text, None),
        Err(e) => {
            // The text before the first bad byte is the same in the lossy copy.
            let at = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            let warning = SceneError::at(
                path,
                &text,
                at..at + '\u{FFFD}'.len_utf8(),
                "this byte is not UTF-8; it and any others like it are read as U+FFFD (�)",
            );
            (text, Some(warning.as_warning()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_that_are_not_utf8_are_replaced_and_located() {
        let (text, warning) = lenient(Path::new("t.nff"), b"# ok\n# caf\xe9\n".to_vec());
        assert_eq!(text, "# ok\n# caf\u{FFFD}\n");
        let warning = warning.unwrap();
        assert!(warning.contains("t.nff:2:6"), "{warning}");
        assert!(warning.starts_with("warning:"), "{warning}");
        assert_eq!(
            lenient(Path::new("t"), b"fine".to_vec()),
            ("fine".into(), None)
        );
    }
}
