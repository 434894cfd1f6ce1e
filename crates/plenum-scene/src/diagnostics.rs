//! Located errors: every problem in a scene file names file:line:column, shows the line with
//! a caret under the culprit, and says what was expected.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneError {
    pub path: PathBuf,
    /// 1-based line and column (in characters) of the problem; 0 when there is no location
    /// (a file that cannot be read at all).
    pub line: usize,
    pub column: usize,
    /// The source line, for the caret display.
    pub source_line: String,
    /// Characters the caret underlines.
    pub width: usize,
    pub message: String,
    /// A suggestion, such as the field name that was probably meant.
    pub help: Option<String>,
}

impl SceneError {
    /// An error at a byte range of `text`.
    pub fn at(path: &Path, text: &str, span: Range<usize>, message: impl Into<String>) -> Self {
        // A span from another layer (an XML parser's position) may fall inside a
        // character: widen it to whole characters.
        let mut start = span.start.min(text.len());
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let source_line = text[line_start..line_end]
            .trim_end_matches('\r')
            .to_string();
        let line = text[..start].matches('\n').count() + 1;
        let column = text[line_start..start].chars().count() + 1;
        let mut end = span.end.clamp(start, line_end);
        while !text.is_char_boundary(end) {
            end += 1;
        }
        let width = text[start..end].chars().count().max(1);
        SceneError {
            path: path.to_path_buf(),
            line,
            column,
            source_line,
            width,
            message: message.into(),
            help: None,
        }
    }

    /// An error about a whole file (it cannot be read).
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        SceneError {
            path: path.to_path_buf(),
            line: 0,
            column: 0,
            source_line: String::new(),
            width: 0,
            message: message.into(),
            help: None,
        }
    }

    /// The message shown as a warning: something read past, not a reason to stop.
    pub fn as_warning(&self) -> String {
        self.to_string().replacen("error:", "warning:", 1)
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            return write!(f, "error: {}: {}", self.path.display(), self.message);
        }
        writeln!(f, "error: {}", self.message)?;
        writeln!(
            f,
            "  --> {}:{}:{}",
            self.path.display(),
            self.line,
            self.column
        )?;
        let gutter = self.line.to_string().len();
        writeln!(f, "{:gutter$} |", "")?;
        writeln!(f, "{} | {}", self.line, self.source_line)?;
        let pad: String = self
            .source_line
            .chars()
            .take(self.column - 1)
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        write!(f, "{:gutter$} | {}{}", "", pad, "^".repeat(self.width))?;
        if let Some(help) = &self.help {
            write!(f, "\n{:gutter$} = help: {help}", "")?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneError {}

/// The candidate closest to `word` by edit distance, if it is close enough to be a typo.
pub fn did_you_mean<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (edit_distance(word, c), c))
        .filter(|&(d, c)| d <= 2.max(c.len() / 3))
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Levenshtein distance, by characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for j in 0..b.len() {
            let substitution = previous + usize::from(ca != b[j]);
            previous = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(previous + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_inside_a_character_covers_the_character() {
        // "é" is bytes 1..3: a span from byte 2 points at it.
        let e = SceneError::at(Path::new("f"), "aéb", 2..3, "m");
        assert_eq!((e.line, e.column, e.width), (1, 2, 1));
    }

    #[test]
    fn location_and_caret() {
        let text = "a = 1\n  radus = 2\n";
        let e = SceneError::at(Path::new("s.toml"), text, 8..13, "unknown field `radus`")
            .with_help("did you mean `radius`?");
        assert_eq!((e.line, e.column, e.width), (2, 3, 5));
        let shown = e.to_string();
        assert!(shown.contains("--> s.toml:2:3"), "{shown}");
        assert!(shown.contains("2 |   radus = 2"));
        assert!(shown.contains("  |   ^^^^^"));
        assert!(shown.contains("did you mean `radius`?"));
    }

    #[test]
    fn suggestions() {
        assert_eq!(did_you_mean("radus", ["center", "radius"]), Some("radius"));
        assert_eq!(
            did_you_mean("colour", ["color", "intensity"]),
            Some("color")
        );
        assert_eq!(did_you_mean("zzz", ["center", "radius"]), None);
    }
}
